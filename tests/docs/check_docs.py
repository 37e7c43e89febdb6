#!/usr/bin/env python3
"""Docs that cannot drift (issue 45): check docs/*.md against the tree and the command line.

    check_docs.py SOURCE_DIR CANDELA [--only identifiers|flags]

identifiers: every code name that docs/*.md writes in an inline code span or a fenced block, and every
  relative link, exists in the tree:
  - file paths (`src/candela/io/scene_reader.cpp`, `bench/distributed.sh`, `io/json/settings.cpp`,
    `film/`, `fuzz/*.dict`, `io/<format>_reader.h`) exist as a file or folder, from the repository
    root, src/candela/, src/candela/io/ or python/; `film/image_io` and `render/render_tiles` name a
    file stem or a word in that folder; a bare C++ source file name (`auto_integrator.h`) exists
    somewhere in the tree;
  - identifiers exist as a whole word in the tree's sources, scripts, CMake files and scenes (src apps
    python tests bench fuzz cmake .ci scenes examples CMakeLists.txt; not the docs, not README.md, not
    this folder, not the fuzz corpora): snake_case names with an underscore (`check_request_values`,
    `max_depth`), CamelCase and camelCase names (`RenderRequest`, `alphaCutoff`), calls (`render()`),
    and names used through the Python module (`candela.load_file`); the parts of a `Qualified::name`
    and of a gtest name (`HostileInput.AbsurdResolution`) all in one file. A JSON key or a pbrt,
    Mitsuba or glTF word that candela reads is a string in its reader, so finding it as a word is
    still an existence check;
  - a `candela ...` command line written in the docs uses only flags that candela's --help lists, and
    so does every code span of docs/cli.md that starts with a flag.
flags: every long flag in `candela --help` and in each subcommand's --help appears in docs/cli.md, and
  so does each subcommand (as `candela NAME`).

Prints one line per problem, `docs/FILE.md:LINE: ...`, and exits 1 if there is any.
What is not candela's code (flags, numbers, environment variables set on a command line, shell
variables, URLs, paths outside the tree, other programs' and libraries' names) is left out by the rules
in `classify`, OUTSIDE_PREFIXES, EXTERNAL_NAMESPACES, EXTERNAL_OWNERS and, last, the short EXTERNAL
list. tests/docs/test_check_docs.py shows that each check can fail.
"""

import argparse
import fnmatch
import glob
import os
import re
import subprocess
import sys

# Where code names are looked for, relative to the source dir.
TREE_ROOTS = ["src", "apps", "python", "tests", "bench", "fuzz", "cmake", ".ci", "scenes", "examples",
              "CMakeLists.txt"]
# Not searched for words: this checker (its own lists would make every name in them exist), and the
# fuzzers' inputs (random mutations of scenes: a key removed from the readers can live on there).
# Paths into them are still checked as paths.
WORDS_SKIP = ["tests/docs", "fuzz/corpus", "fuzz/regressions"]
# Top-level folders of the repository: a token that starts with one is a path.
REPO_ROOTS = {"src", "apps", "python", "tests", "bench", "fuzz", "cmake", ".ci", "scenes", "examples", "docs"}
# The folders of src/candela/ and src/candela/io/: a token that starts with one is a path when it names a
# folder or a source file (they hold nothing else); `textures/wood.png` in a message is not candela's.
MODULE_ROOTS = {"base", "camera", "film", "geometry", "integrators", "io", "lights", "materials", "math",
                "media", "preview", "render", "sampling", "scene", "spectral", "testing", "textures",
                "json", "pbrt", "mitsuba", "gltf", "mesh"}
# Where a relative path may start: `io/gzip.h` is src/candela/io/gzip.h, `json/settings.cpp` is
# src/candela/io/json/settings.cpp, `candela/__init__.py` is python/candela/__init__.py.
PATH_BASES = ["", "src/candela", "src/candela/io", "python"]
# A bare file name with one of these extensions is a C++ source file of the tree (`bdpt.h`); other bare
# names (`scene.json`, `out.exr`, `part.sh`) are examples in the text.
SOURCE_EXTENSIONS = {"h", "hpp", "cpp", "cc", "in", "html", "cmake"}
# A token with a folder and one of these extensions is a path even when its first folder is not one of
# the roots (`candela/__init__.py`); data files (`meshes/cow.obj`) are paths only under REPO_ROOTS,
# elsewhere they are examples in messages.
PATH_EXTENSIONS = SOURCE_EXTENSIONS | {"py", "sh", "md"}
# Path prefixes that are outside the tree: ../shared/ and shared/ (the data beside the repository),
# build folders, absolute paths (also JSON pointers such as /shapes/0 and URL paths such as /stop),
# and `dir/` and `parts/`, the docs' example folders in messages and commands.
OUTSIDE_PREFIXES = ("../", "./", "shared/", "build", "/", "~", "dir/", "parts/")

# C++ namespaces of libraries: `std::variant`, `nanovdb::io`, `Iex::ArgExc` (OpenEXR), `RootNode::`
# (OpenVDB's tree node).
EXTERNAL_NAMESPACES = {"std", "nanovdb", "Iex", "tbb", "oneapi", "openvdb", "RootNode", "OIIO"}
# A code span right after "<owner>'s " (and up to three more words or an opening parenthesis) names the
# owner's code, not candela's: "pbrt-v4's `RGBUnboundedSpectrum`", "CMake's
# `INTERPROCEDURAL_OPTIMIZATION`", "pbrt-v4's sensor curves (`canon_eos_100d_r` ...)".
EXTERNAL_OWNERS = re.compile(
    r"(?:pbrt|pbrt-v[34]|Mitsuba|Mitsuba 3|Tungsten|Embree|OpenVDB|NanoVDB|OpenEXR|OpenImageIO|OIIO|CMake|"
    r"glTF|glibc|Kubernetes|SLURM|Open MPI|MPI|oneTBB|TBB|libFuzzer|Blender|Cycles|tev|NumPy|pybind11|"
    r"GCC|Clang|Python)'s (?:[\w-]+ ){0,3}\(?$")
# Other programs' and formats' names that the docs write in a code span without such an owner, each
# with why. A name is listed here only while it is not in the tree (a listed name that comes to be
# there is reported, so that the list cannot grow stale).
EXTERNAL = {
    "completionMode": "a Kubernetes Job field (distributed.md: an indexed Job on paper)",
    "ReadWriteMany": "a Kubernetes volume access mode (distributed.md)",
    "__tls_get_addr": "glibc's thread-local lookup, seen in a profile (performance.md)",
    "TEXCOORD_n": "glTF's attributes TEXCOORD_0, TEXCOORD_1, ... (the reader formats the names)",
    "KHR_materials_variants": "a glTF extension candela does not read (gltf-format.md's 'Not supported'; "
                              "the reader warns about any extension it does not know, by its name)",
}


def read_text(path):
    try:
        with open(path, "rb") as f:
            data = f.read(8 << 20)
    except OSError:
        return ""
    if b"\0" in data[:8192]:
        return ""
    return data.decode("utf-8", "replace")


def tree_files(src, skip=()):
    skip = [os.path.join(src, s) for s in skip]
    for root in TREE_ROOTS:
        top = os.path.join(src, root)
        if os.path.isfile(top):
            yield top
            continue
        for dirpath, dirnames, filenames in os.walk(top):
            if any(dirpath == s or dirpath.startswith(s + os.sep) for s in skip):
                dirnames[:] = []
                continue
            dirnames[:] = [d for d in dirnames if d != "__pycache__"]
            for name in filenames:
                yield os.path.join(dirpath, name)


def tree_words(src):
    """{word: the indices of the files it is in} for every word ([A-Za-z_][A-Za-z0-9_]*) in the text
    files under TREE_ROOTS, also the names after -D (`-DCANDELA_BUILD_PYTHON=OFF`), and snake_case forms
    of hyphenated names (`veach-bidir` is the test case `veach_bidir`)."""
    words = {}
    for index, path in enumerate(tree_files(src, WORDS_SKIP)):
        text = read_text(path)
        found = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", text))
        found.update(re.findall(r"(?<![\w-])-D([A-Za-z_]\w*)", text))
        found.update(w.replace("-", "_") for w in re.findall(r"[A-Za-z_][\w-]*-[\w-]*\w", text))
        for word in found:
            words.setdefault(word, set()).add(index)
    # The fuzz targets: fuzz/CMakeLists.txt builds fuzz_<target> from fuzz/<target>_fuzz.cpp.
    for path in glob.glob(os.path.join(src, "fuzz", "*_fuzz.cpp")):
        words.setdefault("fuzz_" + os.path.basename(path)[: -len("_fuzz.cpp")], {-1})
    return words


def tree_file_names(src):
    return {os.path.basename(path) for path in tree_files(src)}


# ---------------------------------------------------------------------------------------------------
# Extracting the code in a Markdown file


def code_pieces(text):
    """(line number, code text, the prose before it: the line's and the line's before) for each inline
    code span and each line of a fenced block."""
    pieces = []
    fence = None
    previous = ""
    for number, line in enumerate(text.split("\n"), 1):
        stripped = line.lstrip()
        before, previous = previous, line
        if fence is not None:
            if stripped.startswith(fence):
                fence = None
            else:
                pieces.append((number, line, ""))
            continue
        m = re.match(r"(```+|~~~+)", stripped)
        if m:
            fence = m.group(1)
            continue
        for span in re.finditer(r"(?<!`)(`+)(?!`)(.+?)(?<!`)\1(?!`)", line):
            pieces.append((number, span.group(2).strip(), re.sub(r"\s+", " ", before + " " + line[: span.start()]).lstrip()))
    return pieces


def links(text):
    """(line number, target) of each relative Markdown link (not a URL, not an anchor of this file)."""
    found = []
    for number, line in enumerate(text.split("\n"), 1):
        line = re.sub(r"(`+).+?\1", "", line)
        for m in re.finditer(r"\]\(([^)\s]+)\)", line):
            target = m.group(1).split("#")[0]
            if target and not re.match(r"[a-z]+:", target):
                found.append((number, target))
    return found


CAMEL = re.compile(r"[A-Z]+[a-z0-9]+[A-Z]|[a-z]+[0-9]*[A-Z]")
PLACEHOLDER = re.compile(r"<[^<>/]*>")


def is_code_name(word):
    """A word that names code: snake_case (with an underscore), CamelCase or camelCase."""
    if word[0].isdigit() or not re.search(r"[A-Za-z]", word):
        return False
    if "_" in word.strip("_*") or word.startswith("__"):
        return True
    return bool(CAMEL.match(word))


def candela_flags(text):
    """The long flags of a `candela` command line in `text`: those after a word `candela` or
    `.../candela` that is the command (not a flag's value, as in `--candela build/candela`)."""
    tokens = text.split()
    for i, token in enumerate(tokens):
        if re.fullmatch(r"(?:\S*/)?candela", token) and not (i > 0 and tokens[i - 1].startswith("-")):
            return [t.split("=")[0] for t in tokens[i + 1:] if re.match(r"--[a-z]", t)]
    return []


def classify(code):
    """Split a piece of code into (paths, names, flags): the paths and identifiers it names that are to
    exist in the tree, and the long flags of the `candela` command line in it."""
    paths, names = [], []
    text = re.sub(r"[a-z]+://\S+", " ", code)                      # URLs
    text = re.sub(r"\$\{?\w+\}?", " ", text)                        # shell and Mitsuba $variables
    flags = candela_flags(re.sub(r"(?:^|\s)#.*", "", text))       # not in a shell comment
    # CMake cache variables given with -D are the tree's (`-DCANDELA_BUILD_PYTHON=OFF`).
    names += re.findall(r"(?<![\w-])-D([A-Z][A-Z0-9_]+)=", text)
    # Flags and options of any program (`--spp`, `-fsanitize=address`, `-np 3`).
    text = re.sub(r"(?<![\w./<>*-])--?[A-Za-z][\w-]*(?![\w/.])(?:=\S*)?", " ", text)
    # Environment variables set on a command line (`FUZZ_SEED=0 fuzz/run.sh`): names of the process's
    # environment, some of them other programs' (`PYTHONPATH=...`).
    text = re.sub(r"(?:^|(?<=\s))[A-Z][A-Z0-9_]*=\S*", " ", text)
    # Paths: a token with a slash whose first folder is one of the tree's, or whose last part has a
    # file extension of the tree's sources; and bare source file names (`*_test.cpp` is a pattern).
    for m in re.finditer(r"(?<![\w.:/<>*-])((?:\.\.?/)*[\w.<>*+-]*(?:/[\w.<>*+-]*)+)", text):
        token = re.sub(r"-+>$", "", m.group(1).rstrip(".").lstrip("-"))  # arrows: `--io/x.cpp-->`
        first = token.split("/")[0]
        last = token.rstrip("/").split("/")[-1]
        extension = last.rsplit(".", 1)[-1] if "." in last else ""
        if token.startswith(OUTSIDE_PREFIXES) or first in REPO_ROOTS or extension in PATH_EXTENSIONS \
                or first in MODULE_ROOTS and extension in SOURCE_EXTENSIONS | {""}:
            paths.append(token)
            text = text.replace(token, " ", 1)
    for m in re.finditer(r"(?<![\w./-])([\w*<>-]+\.([a-z]+))(?![\w/])", text):
        if m.group(2) in SOURCE_EXTENSIONS:
            paths.append(m.group(1))
    text = re.sub(r"(?<![\w./-])[\w*<>-]+\.(?:%s)(?![\w/])" % "|".join(SOURCE_EXTENSIONS), " ", text)
    # Qualified names (`SceneDesc::places`, `Scene::shading(hit)`), unless a library's, and gtest names
    # (`HostileInput.AbsurdResolution`): their parts are to be in one file (name_exists).
    for m in re.finditer(r"\b(\w+(?:::~?\w+\*?)+)", text):
        if m.group(1).split("::")[0] not in EXTERNAL_NAMESPACES:
            names.append(m.group(1).replace("~", ""))
    text = re.sub(r"\b\w+(?:::~?\w+\*?)+", " ", text)
    names += [m.group(0) for m in re.finditer(r"(?<![\w.])[A-Z][A-Za-z0-9]*\.[A-Z][A-Za-z0-9]*(?![\w.])", text)
              if all(is_code_name(part) for part in m.group(0).split("."))]
    text = re.sub(r"(?<![\w.])[A-Z][A-Za-z0-9]*\.[A-Z][A-Za-z0-9]*(?![\w.])", lambda m: " " if all(
        is_code_name(part) for part in m.group(0).split(".")) else m.group(0), text)
    # Names used through the Python module: `candela.render_keywords()`, `candela.SceneError`.
    names += re.findall(r"(?<![\w.])candela\.([A-Za-z_]\w*)", text)
    text = re.sub(r"(?<![\w.])candela\.[A-Za-z_]\w*", " ", text)
    # Calls without a receiver: `render()`, `read_scene_file(path)` (not `np.mean(...)`).
    names += re.findall(r"(?<![\w.])([A-Za-z_]\w*)\(", text)
    # Every other code name, also the parts of other dotted names (`render.transform_times`).
    names += [w for w in re.findall(r"(?<![\w])([A-Za-z_]\w*\*?)", text) if is_code_name(w)]
    return paths, names, flags


def name_exists(name, words):
    """A word of the tree; a name ending in * (`half_*`) is a prefix of one; the parts of a qualified or
    dotted name (`Film::splats`, `MeshIo.PlyWithTwoFormatLinesIsAnError`) are all in one file."""
    files = None
    for part in re.split(r"::|\.", name):
        if part.endswith("*"):
            found = set().union(*[f for w, f in words.items() if w.startswith(part[:-1])])
        else:
            found = words.get(part, set())
        files = found if files is None else files & found
        if not files:
            return False
    return True


def path_exists(src, token, file_names, words):
    if token.startswith(OUTSIDE_PREFIXES):
        return True
    pattern = PLACEHOLDER.sub("*", token)
    if "/" not in pattern:                                          # a bare source file name
        return any(fnmatch.fnmatch(name, pattern) for name in file_names)
    for base in PATH_BASES:
        candidate = os.path.join(src, base, pattern)
        if glob.glob(candidate) if glob.has_magic(candidate) else os.path.exists(candidate):
            return True
    # `film/image_io`, `render/render_tiles`, `film/Film`: a folder of the tree and a file or a name
    # in it.
    folder, _, name = pattern.rstrip("/").rpartition("/")
    if "." not in name and "*" not in pattern:
        for base in PATH_BASES:
            directory = os.path.join(src, base, folder)
            if os.path.isdir(directory) and (
                    glob.glob(os.path.join(directory, name + ".*"))
                    or any(re.search(rf"\b{re.escape(name)}\b", read_text(os.path.join(directory, f)))
                           for f in os.listdir(directory))):
                return True
    return False


def check_identifiers(src, known_flags):
    """Problems with the code names, paths, links and candela command lines of docs/*.md."""
    words = tree_words(src)
    file_names = tree_file_names(src)
    problems = []
    for name in sorted(n for n in EXTERNAL if n in words):
        problems.append(f"tests/docs/check_docs.py:1: EXTERNAL lists '{name}', which is in the tree now")
    for doc in sorted(glob.glob(os.path.join(src, "docs", "*.md"))):
        rel = os.path.relpath(doc, src)
        text = read_text(doc)
        seen = set()

        def report(kind, token, message):
            if (kind, token) not in seen:
                seen.add((kind, token))
                problems.append(message)

        for number, code, before in code_pieces(text):
            if EXTERNAL_OWNERS.search(before):
                continue
            paths, names, flags = classify(code)
            for token in paths:
                if not path_exists(src, token, file_names, words):
                    report("path", token, f"{rel}:{number}: path '{token}' not found in the tree")
            for name in names:
                if not name_exists(name, words) and name not in EXTERNAL:
                    report("name", name, f"{rel}:{number}: identifier '{name}' not found in the tree")
            if known_flags is not None:
                if rel == os.path.join("docs", "cli.md") and code.startswith("--"):
                    flags = flags + re.findall(r"^(--[a-z][a-z0-9-]*)", code)
                for flag in flags:
                    if flag not in known_flags:
                        report("flag", flag, f"{rel}:{number}: flag '{flag}' is not in candela's --help")
        for number, target in links(text):
            if not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(doc), target))):
                problems.append(f"{rel}:{number}: link target '{target}' not found")
    return problems



# ---------------------------------------------------------------------------------------------------
# The command line


def help_text(candela, *args):
    result = subprocess.run([candela, *args, "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, timeout=60)
    if result.returncode != 0:
        raise RuntimeError(f"{candela} {' '.join(args)} --help exited {result.returncode}:\n{result.stdout}")
    return result.stdout


def section(text, title):
    """The lines of a CLI11 help section (`Options:`, `Subcommands:`)."""
    m = re.search(rf"^{title}:\n((?:[ \t]+\S.*\n?)+)", text, re.M)
    return m.group(1).splitlines() if m else []


def help_flags(candela):
    """{subcommand ('' for candela itself): [long flags]} from the --help texts."""
    top = help_text(candela)
    subcommands = [line.split()[0] for line in section(top, "Subcommands")]
    flags = {}
    for sub in [""] + subcommands:
        text = top if sub == "" else help_text(candela, sub)
        flags[sub] = [m.group(1) for line in section(text, "Options")
                      for m in [re.match(r"\s+(?:-\w,)?(--[\w-]+)", line)] if m]
    return flags


def check_cli_flags(src, flags):
    problems = []
    cli = os.path.join(src, "docs", "cli.md")
    text = read_text(cli)
    rel = os.path.relpath(cli, src)
    for sub, sub_flags in flags.items():
        command = f"candela {sub}".strip()
        if sub and not re.search(rf"\bcandela {re.escape(sub)}\b", text):
            problems.append(f"{rel}:1: subcommand '{command}' is not documented")
        for flag in sub_flags:
            if not re.search(rf"(?<![\w-]){re.escape(flag)}(?![\w-])", text):
                problems.append(f"{rel}:1: flag '{flag}' of '{command}' is not documented")
    return problems


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("source_dir")
    parser.add_argument("candela", help="the candela binary, run with --help")
    parser.add_argument("--only", choices=["identifiers", "flags"])
    args = parser.parse_args(argv)
    src = os.path.abspath(args.source_dir)
    try:
        flags = help_flags(args.candela)
    except (OSError, RuntimeError, subprocess.TimeoutExpired) as e:
        print(f"check_docs.py: cannot read candela's --help: {e}", file=sys.stderr)
        return 2
    known = {f for fs in flags.values() for f in fs}
    problems = []
    if args.only in (None, "identifiers"):
        problems += check_identifiers(src, known)
    if args.only in (None, "flags"):
        problems += check_cli_flags(src, flags)
    for problem in problems:
        print(problem)
    if problems:
        print(f"{len(problems)} problem(s) in docs/ (tests/docs/check_docs.py says what is checked)",
              file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
