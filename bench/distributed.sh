#!/usr/bin/env bash
# Distributed rendering on one machine (docs/distributed.md): Open MPI ranks against one process.
#   bench/distributed.sh [CANDELA]      (default build/candela; RES, SPP override the Cornell box's size)
# Prints, from the candela closing lines:
#   1. speed: one process with 2 threads against mpirun -np 2 with 1 thread per rank (Cornell box);
#   2. work conservation: the ranks' busy CPU seconds with 1, 2, 4 and 8 ranks (4 and 8 oversubscribed)
#      against one rank's, and the bytes each rank sent;
#   3. load balance: on a scene whose cost sits in one corner (bench/scenes/corner_cost.json), the
#      spread of the ranks' busy times.
# Every MPI image is also compared with the one-process image (they must be the same bytes).
set -euo pipefail
cd "$(dirname "$0")/.."
candela=${1:-build/candela}
res=${RES:-512x512}
spp=${SPP:-256}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpirun="mpirun --oversubscribe --bind-to none"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

seconds() { sed -nE 's/.* in ([0-9.]+) s:.*/\1/p' <<<"$1"; }
busy() { sed -nE 's/.*busy thread-seconds per rank: ([0-9. ]+)\).*/\1/p' <<<"$1"; }
sent() { sed -nE 's/.*sent per rank: at most ([0-9.]+) MB.*/\1/p' <<<"$1"; }
collective() { sed -nE 's/.*rank 0 in collectives ([0-9.]+) s.*/\1/p' <<<"$1"; }
sum() { tr ' ' '\n' <<<"$1" | awk '{s += $1} END {printf "%.2f", s}'; }
spread() { tr ' ' '\n' <<<"$1" | awk 'NR == 1 {lo = hi = $1} {if ($1 < lo) lo = $1; if ($1 > hi) hi = $1; s += $1}
                                        END {printf "%.1f%%", 100 * (hi - lo) / (s / NR)}'; }
same() { cmp -s "$out/one.pfm" "$1" && echo identical || echo DIFFERENT; }

scene=scenes/cornell-box.json
echo "== Cornell box $res, $spp spp, path ($(nproc) cores)"
one=$($mpirun -np 1 "$candela" render $scene -q --resolution "$res" --spp "$spp" --threads 2 -o "$out/one.pfm")
t1=$(seconds "$one")
printf "%-34s %8s s  busy %8s s\n" "1 rank x 2 threads" "$t1" "$(sum "$(busy "$one")")"
two=$($mpirun -np 2 "$candela" render $scene -q --resolution "$res" --spp "$spp" --threads 1 -o "$out/two.pfm")
t2=$(seconds "$two")
printf "%-34s %8s s  busy %8s s  speed %s x one process  sent %s MB/rank  rank 0 in collectives %s s  %s\n" \
  "2 ranks x 1 thread" "$t2" "$(sum "$(busy "$two")")" "$(awk -v a="$t1" -v b="$t2" 'BEGIN {printf "%.3f", a / b}')" \
  "$(sent "$two")" "$(collective "$two")" "$(same "$out/two.pfm")"
base=$($mpirun -np 1 "$candela" render $scene -q --resolution "$res" --spp "$spp" --threads 1 -o "$out/base.pfm")
b1=$(sum "$(busy "$base")")
printf "%-34s %8s s  busy %8s s\n" "1 rank x 1 thread" "$(seconds "$base")" "$b1"
for n in 4 8; do
  r=$($mpirun -np $n "$candela" render $scene -q --resolution "$res" --spp "$spp" --threads 1 -o "$out/n$n.pfm")
  b=$(sum "$(busy "$r")")
  printf "%-34s %8s s  busy %8s s  (%s of one rank's)  sent %s MB/rank  rank 0 in collectives %s s  %s\n" \
    "$n ranks x 1 thread (oversubscribed)" "$(seconds "$r")" "$b" \
    "$(awk -v a="$b" -v b="$b1" 'BEGIN {printf "%+.1f%%", 100 * (a / b - 1)}')" "$(sent "$r")" "$(collective "$r")" \
    "$(same "$out/n$n.pfm")"
done

echo "== Load balance: bench/scenes/corner_cost.json (all the cost in one corner)"
for n in 2 4; do
  r=$($mpirun -np $n "$candela" render bench/scenes/corner_cost.json -q --threads 1 -o "$out/corner$n.pfm")
  printf "%-34s %8s s  busy per rank: %s  spread (max - min) / mean: %s\n" "$n ranks x 1 thread" \
    "$(seconds "$r")" "$(busy "$r")" "$(spread "$(busy "$r")")"
done
