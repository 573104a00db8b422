"""Side by side (lowerlimb.side_by_side): the same results, errors raised as without a child.

The side-by-side path forks, which the runner refuses in a process with other threads (a
pytest-xdist worker has them), so it is tested in a fresh interpreter.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading

import pytest

from lowerlimb.bilateral.leg_runner import LegWarning, run_two_legs
from lowerlimb.side_by_side import possible, set_enabled


def _fresh(code: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, env=env, timeout=300
    )


def test_one_after_the_other_in_order_in_this_process():
    order: list[str] = []

    def run(side: str) -> tuple[int, list[LegWarning]]:
        order.append(side)
        return os.getpid(), [LegWarning(side, UserWarning)]

    legs = run_two_legs(run, parallel=False)
    assert order == ["left", "right"]
    assert legs["right"] == (os.getpid(), [LegWarning("right", UserWarning)])


def test_no_fork_while_another_thread_runs():
    stop = threading.Event()
    thread = threading.Thread(target=stop.wait)
    thread.start()
    try:
        assert not possible()
        legs = run_two_legs(lambda side: (os.getpid(), []), parallel=True)
        assert legs["left"][0] == legs["right"][0] == os.getpid()
    finally:
        stop.set()
        thread.join()


def test_turned_off_it_runs_here():
    set_enabled(False)
    try:
        assert not possible()
    finally:
        set_enabled(True)


@pytest.mark.skipif(not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2, reason="no fork")
def test_side_by_side_the_right_leg_runs_in_a_child_and_its_lines_follow_the_left():
    out = _fresh(
        """
        import os, sys
        from lowerlimb.bilateral.leg_runner import LegWarning, run_two_legs
        def run(side):
            print(f"{side} line", file=sys.stderr)
            return os.getpid(), [LegWarning(f"{side} warned", RuntimeWarning)]
        legs = run_two_legs(run)
        print(legs["left"][0] == os.getpid(), legs["right"][0] != os.getpid(), legs["right"][1])
        from lowerlimb.side_by_side import possible, side_by_side
        print(side_by_side(possible, possible), possible())  # nothing nested, here or in the child
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[1] == "(False, False) True"
    relayed = "[LegWarning(message='right warned', category=<class 'RuntimeWarning'>)]"
    assert out.stdout.split("\n")[0] == f"True True {relayed}"
    assert out.stderr.splitlines() == ["left line", "right line"]


@pytest.mark.skipif(not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2, reason="no fork")
def test_side_by_side_a_failing_leg_is_raised_here_with_its_type_and_data():
    out = _fresh(
        """
        import os
        from lowerlimb.bilateral.leg_runner import run_two_legs
        class Odd(Exception):  # its constructor's arguments are not its args: it does not unpickle
            def __init__(self, value):
                super().__init__(f"odd {value}")
                self.value = value
        r, w = os.pipe()
        def run(side):
            if side == "right":
                os.write(w, f"{os.getpid()} ".encode())
                raise Odd(os.getpid())
            return 0, []
        try:
            run_two_legs(run)
        except Odd as e:
            os.close(w)
            tried = os.read(r, 1000).decode().split()
            print(e.value == os.getpid(), len(set(tried)))
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "2"]  # tried in the child, raised from here


@pytest.mark.skipif(not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2, reason="no fork")
def test_side_by_side_and_one_after_the_other_give_the_same_two_legs():
    out = _fresh(
        """
        import sys, warnings
        import numpy as np
        sys.path.insert(0, "tests")
        from bilateral_sim import simulate_two_legs
        from lowerlimb.bilateral import process_bilateral_trial
        trial = simulate_two_legs(7, 20.0).trial
        runs = {}
        for parallel in (True, False):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                r = process_bilateral_trial(trial, parallel_legs=parallel)
            runs[parallel] = r, sorted(str(w.message) for w in caught)
        (a, wa), (b, wb) = runs[True], runs[False]
        same = np.array_equal(a.angles_rad, b.angles_rad), np.array_equal(a.positions_m, b.positions_m)
        print(*same, wa == wb)
        for side in ("left", "right"):
            print(np.array_equal(a.legs[side].calibration.knee.axis_in_parent_sensor,
                                 b.legs[side].calibration.knee.axis_in_parent_sensor))
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "True", "True", "True", "True"]


@pytest.mark.skipif(not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2, reason="no fork")
def test_the_report_is_the_same_page_with_its_figures_side_by_side():
    out = _fresh(
        """
        import re, sys, tempfile
        from pathlib import Path
        sys.path.insert(0, "tests")
        from simcache import cached_simulation
        import lowerlimb.side_by_side as sbs
        from lowerlimb.viz.report import write_report
        sim = cached_simulation("walk", 20.0, 1)
        pages = []
        with tempfile.TemporaryDirectory() as d:
            for flag in (True, False):
                sbs.set_enabled(flag)
                path = Path(d) / f"{flag}.html"
                write_report(path, model=sim.model, time_s=sim.trial.time_s, angles_rad=sim.angles_rad,
                             positions_m=sim.positions_m, calibration=sim.model.calibration_dict("casadi"))
                pages.append(path.read_text())
        pngs = [re.findall(r"data:image/png;base64,[A-Za-z0-9+/=]+", page) for page in pages]
        print(pngs[0] == pngs[1], len(pngs[0]))  # the scene's object ids differ from run to run
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "3"]


@pytest.mark.skipif(not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2, reason="no fork")
def test_work_beside_is_dropped_when_not_needed_and_run_here_when_the_child_fails(tmp_path):
    out = _fresh(
        f"""
        import os, time
        from pathlib import Path
        from lowerlimb.side_by_side import Beside, possible
        mark = Path({str(tmp_path)!r}) / "late"
        def slow():
            time.sleep(1.0)
            mark.write_text("ran")
            return os.getpid()
        with Beside(slow) as beside:
            inside = possible()
        time.sleep(1.5)
        print(inside, mark.exists(), possible())  # dropped: it never finished
        with Beside(lambda: os.getpid()) as beside:
            print(beside.value() != os.getpid())  # taken from the child
        with Beside(lambda: 1 / 0) as beside:
            try:
                beside.value()
            except ZeroDivisionError:
                print("raised here")
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == ["False False True", "True", "raised here"]


@pytest.mark.skipif(not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2, reason="no fork")
def test_the_widened_fit_beside_the_coherent_one_gives_the_same_leg():
    out = _fresh(
        """
        import warnings
        import numpy as np
        import lowerlimb.side_by_side as sbs
        from lowerlimb.pipeline import process_trial
        from lowerlimb.simulation import simulate_bilateral
        trial = simulate_bilateral(40.0, 201).trial.leg("left")
        runs = []
        for flag in (True, False):
            sbs.set_enabled(flag)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                r = process_trial(trial, leg_gait=False)
            runs.append((r, sorted(str(w.message) for w in caught)))
        (a, wa), (b, wb) = runs
        c, d = a.calibration, b.calibration
        same = np.array_equal
        print(c.fit_band.widened, c.fit_band == d.fit_band, same(a.angles_rad, b.angles_rad), wa == wb)
        print(same(c.hip.center_in_child_sensor, d.hip.center_in_child_sensor),
              same(c.coherent_fit.knee.axis_in_parent_sensor, d.coherent_fit.knee.axis_in_parent_sensor))
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True"] * 6


@pytest.mark.skipif(not sys.platform.startswith("linux") or (os.cpu_count() or 1) < 2, reason="no fork")
def test_a_dropped_child_blocked_on_a_large_value_ends_and_raw_threads_forbid_forking():
    out = _fresh(
        """
        import _thread, signal, time
        import numpy as np
        from lowerlimb.side_by_side import Beside, possible
        def stop(signum, frame):  # as the command line does: SIGTERM raises
            raise SystemExit(143)
        signal.signal(signal.SIGTERM, stop)
        t0 = time.perf_counter()
        with Beside(lambda: np.ones(4_000_000)) as beside:
            time.sleep(1.0)  # the child is blocked sending 32 MB nobody reads
        print(time.perf_counter() - t0 < 10.0)
        with Beside(lambda: np.ones(4_000_000)) as beside:
            print(float(beside.value().sum()))
        _thread.start_new_thread(time.sleep, (5.0,))  # a thread threading does not count
        print(possible())
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "4000000.0", "False"]
