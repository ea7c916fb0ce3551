"""Long calls release the GIL: another Python thread makes progress while they run."""
import threading
import time

import geode


def longest_stall(call):
    """Runs call() in a thread while this one ticks; returns (its result, its seconds, the longest
    gap between two ticks). A call holding the GIL stalls the ticking for as long as it runs."""
    done = threading.Event()
    result = {}

    def work():
        start = time.perf_counter()
        result["value"] = call()
        result["seconds"] = time.perf_counter() - start
        done.set()

    worker = threading.Thread(target=work)
    last = time.perf_counter()
    gap = 0.0
    worker.start()
    while not done.is_set():
        time.sleep(0.001)
        now = time.perf_counter()
        gap, last = max(gap, now - last), now
    worker.join()
    return result["value"], result["seconds"], gap


def test_template_releases_the_gil():
    t, seconds, gap = longest_stall(lambda: geode.template("geode4tri"))
    assert len(t.hexes) == 56
    assert seconds > 0.2 and gap < 0.5 * seconds, (seconds, gap)


def test_conform_releases_the_gil():
    # The reference templates are built once per process: a model big enough that the call
    # alone takes well over the 0.2 s the check needs (n = 24: about 0.4 s on 2 cores).
    model = geode.demo_model("delaunay", 24)
    (mesh, report), seconds, gap = longest_stall(lambda: geode.conform(model))
    assert report["valid"]
    assert seconds > 0.2 and gap < 0.5 * seconds, (seconds, gap)


def test_the_check_sees_a_held_gil():
    # The control: libc's sleep called through ctypes.PyDLL keeps the GIL for the whole call, and
    # the ticking thread stalls for about as long.
    import ctypes

    _, seconds, gap = longest_stall(lambda: ctypes.PyDLL(None).usleep(300000))
    assert seconds > 0.25 and gap >= 0.5 * seconds, (seconds, gap)
