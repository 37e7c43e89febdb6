"""Ctrl-C during a render: KeyboardInterrupt within a second, the interpreter intact."""
import os
import signal
import subprocess
import sys
import textwrap
import time

from conftest import furnace_dict

SCRIPT = textwrap.dedent("""
    import sys, time, candela
    scene = candela.load_dict({scene!r})
    print("rendering", flush=True)
    try:
        candela.render(scene, spp=1 << 20, resolution=(256, 256), progress=False)
        print("finished", flush=True)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
    # The interpreter and the module still work afterwards.
    print(candela.render(scene, spp=1, resolution=(4, 4), progress=False).shape, flush=True)
""")


def test_ctrl_c_stops_a_render_within_a_second():
    child = subprocess.Popen([sys.executable, "-c", SCRIPT.format(scene=furnace_dict())], stdout=subprocess.PIPE,
                             text=True, env=os.environ)
    assert child.stdout.readline().strip() == "rendering"
    time.sleep(1.0)  # well into the render (minutes long)
    start = time.monotonic()
    child.send_signal(signal.SIGINT)
    line = child.stdout.readline().strip()
    stopped = time.monotonic() - start
    child.wait(timeout=60)
    rest = child.stdout.read()  # not communicate(): readline() may have buffered these lines already
    assert line == "interrupted"
    assert stopped < 1.0, f"took {stopped:.2f} s"
    assert "(4, 4, 3)" in rest and child.returncode == 0


def test_a_signal_handled_by_python_code_reaches_it_during_a_render():
    import candela
    import threading
    scene = candela.load_dict(furnace_dict())
    received = []
    previous = signal.signal(signal.SIGUSR1, lambda *_: received.append(time.monotonic()))
    try:
        sent = []
        timer = threading.Timer(0.3, lambda: (sent.append(time.monotonic()), os.kill(os.getpid(), signal.SIGUSR1)))
        timer.start()
        candela.render(scene, spp=256, resolution=(256, 256), progress=False)
        timer.join()
    finally:
        signal.signal(signal.SIGUSR1, previous)
    assert received and received[0] - sent[0] < 0.5
