"""The main job against its physics: wall, CPU and memory per stage, and the plant's rate.

Runs the README's first command's campaign (``artic campaign --out-dir DIR``, on
all cores) ``--runs`` times (default three), each in a fresh process and a fresh
folder, and prints the median and range over the runs of

- each stage's wall time (the campaign's own ``timings.json``) and the CPU time
  of the whole process tree over the stage (the command and every worker and
  warm-up process it starts, read with psutil when the stage's progress line
  opens and closes it);
- the multibody seconds each stage simulated (the plant's and the truth's runs,
  :class:`artic.validation.plumbing.budget.Budget`) and what they would cost at the
  plant's own rate: the simulated steps (at the logs' 10 ms) times the plant's
  measured CPU time a step (:class:`artic.Plant` stepped at 100 Hz in this
  process, RK4 at its 10 ms, a constant steer at 5 km/h). ``CPU / physics`` is
  then the gap between what a stage costs and the multibody steps it needs: 1
  would be a stage that does nothing but step the plant. The truth is costed at
  the plant's rate too (its own model steps at a similar cost);
- the whole run's wall and CPU time and its peak memory: the largest single
  process's resident set (what ``/usr/bin/time -v`` reports) and the peak of the
  tree's summed resident sets, sampled every 0.2 s (an upper bound: it counts
  pages the processes share once per process), and per stage the peak of the
  tree's summed resident sets over the stage (the same samples, between the
  stage's opening and closing lines).

Options: ``--runs N``; ``--no-recordings`` (the campaign's own option);
``--only`` (the campaign's, to try the benchmark on a part); ``--cold-cache``
gives each run an empty home cache (``XDG_CACHE_HOME``), so that numba
compiles what the command's cache lacks: a new user's first run.
Run: ``python benchmarks/bench_campaign.py`` (about two and a half minutes a run on two
quiet cores). The figures are meant for a quiet machine; under load the CPU
columns stay meaningful, the wall columns do not.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

DT = 0.01
"""The logs' sample period, at which the plant is stepped and its steps counted [s]."""

PLANT_SECONDS = 20.0
"""Simulated time over which the plant's cost a step is measured [s]."""

SAMPLE = 0.2
"""Interval of the memory samples [s]."""


def plant_cpu_per_step() -> float:
    """CPU time of one 10 ms plant step, RK4, constant steer at 5 km/h, in this process [s]."""
    from artic.mjcf.interface import InitialState
    from artic.mjcf.vehicle import load_vehicle
    from artic.plant import Plant

    with Plant(load_vehicle("gosar2022-unloaded")) as p:
        p.reset(InitialState(0.0, 0.0, 0.0, 0.0, u1=5 / 3.6))
        for _ in range(100):  # warm: the first steps allocate
            p.step(DT, 0.1, 5 / 3.6, 0.0)
        n = round(PLANT_SECONDS / DT)
        t0 = time.process_time()
        for _ in range(n):
            p.step(DT, 0.1, 5 / 3.6, 0.0)
        return (time.process_time() - t0) / n


def stage_of(line: str) -> str | None:
    """The stage a campaign's progress line opens (``== NAME``) or closes (``== NAME: ...``)."""
    if not line.startswith("== "):
        return None
    return line[3:].rstrip("\n").partition(":")[0]


def _tree_cpu(proc) -> float:
    """CPU time of ``proc``, its waited-for children and its live descendants [s]."""
    import psutil

    try:
        t = proc.cpu_times()
        total = t.user + t.system + t.children_user + t.children_system
        for child in proc.children(recursive=True):
            try:
                c = child.cpu_times()
                total += c.user + c.system
            except psutil.NoSuchProcess:
                pass
        return total
    except psutil.NoSuchProcess:
        return float("nan")


def _tree_rss(proc) -> int:
    """Summed resident set of ``proc`` and its descendants [bytes]."""
    import psutil

    total = 0
    for p in [proc, *proc.children(recursive=True)]:
        try:
            total += p.memory_info().rss
        except psutil.NoSuchProcess:
            pass
    return total


def run_once(recordings: bool, cold_cache: bool, only: str = "") -> dict:
    """One campaign from an empty folder; its stages' wall, CPU and budget, and the run's."""
    import psutil

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        env = dict(os.environ)
        env.pop("NUMBA_CACHE_DIR", None)  # the command's own cache, as a user's run
        if cold_cache:
            env["XDG_CACHE_HOME"] = str(Path(tmp) / "cache")
        argv = ["campaign", "--out-dir", str(out)] + ([] if recordings else ["--no-recordings"])
        argv += ["--only", only] if only else []
        code = ("import sys; from artic.validation.cli.entry import main; "
                f"sys.exit(main({argv!r}))")
        t0 = time.perf_counter()
        child = subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE, text=True)
        proc = psutil.Process(child.pid)
        peak = [0]
        samples: list[tuple[float, int]] = []  # (time, tree RSS) for the stages' peaks
        done = threading.Event()

        def sample() -> None:
            while not done.wait(SAMPLE):
                try:
                    rss = _tree_rss(proc)
                except psutil.NoSuchProcess:
                    return
                peak[0] = max(peak[0], rss)
                samples.append((time.perf_counter(), rss))

        sampler = threading.Thread(target=sample, daemon=True)
        sampler.start()
        cpu_at: dict[str, list[float]] = {}
        when: dict[str, list[float]] = {}
        tail = []
        for line in child.stderr:  # "== NAME" opens a stage, "== NAME: ..." closes it
            tail = (tail + [line])[-20:]
            if (name := stage_of(line)) is not None:
                cpu_at.setdefault(name, []).append(_tree_cpu(proc))
                when.setdefault(name, []).append(time.perf_counter())
        # This run's own rusage: its CPU and its largest process's resident set, the
        # command's and every descendant's it waited for (as /usr/bin/time -v reads them).
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        wall = time.perf_counter() - t0
        done.set()
        sampler.join()
        if child.returncode != 0:
            raise SystemExit("the campaign failed:\n" + "".join(tail))
        timings = json.loads((out / "timings.json").read_text())
    stages = {}
    for name, wall_s in timings["stages"].items():
        marks = cpu_at.get(name, [])
        budget = timings.get("budget", {}).get(name, {})
        span = when.get(name, [])
        inside = [r for t, r in list(samples) if len(span) >= 2 and span[0] <= t <= span[-1]]
        stages[name] = {"wall": wall_s,
                        "cpu": marks[-1] - marks[0] if len(marks) >= 2 else float("nan"),
                        "multibody_s": float(budget.get("multibody", (0, 0.0))[1]),
                        "reduced_s": float(budget.get("reduced", (0, 0.0))[1]),
                        "rss": max(inside) if inside else float("nan")}
    largest = usage.ru_maxrss * 1024  # kB on Linux
    return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "stages": stages,
            "largest_rss": largest, "tree_rss": peak[0]}


def _med(values: list[float], fmt: str = "{:.1f}") -> str:
    """Median and range, as ``median (low-high)``."""
    values = [v for v in values if v == v]
    if not values:
        return "-"
    if len(values) == 1:
        return fmt.format(values[0])
    return (f"{fmt.format(statistics.median(values))} "
            f"({fmt.format(min(values))}-{fmt.format(max(values))})")


def main(runs: int = 3, recordings: bool = True, cold_cache: bool = False,
         only: str = "") -> dict[str, float]:
    step = plant_cpu_per_step()
    print(f"plant: {step * 1e6:.0f} us of CPU a 10 ms step ({DT / step:.0f}x real time on "
          "one core)", flush=True)
    results = []
    for k in range(runs):
        r = run_once(recordings, cold_cache, only)
        results.append(r)
        print(f"run {k + 1}: {r['wall']:.1f} s wall, {r['cpu']:.1f} s CPU, largest process "
              f"{r['largest_rss'] / 1e6:.0f} MB, tree {r['tree_rss'] / 1e6:.0f} MB", flush=True)
    names = list(results[0]["stages"])
    print(f"\ncampaign{'' if recordings else ' --no-recordings'}"
          f"{' (cold numba cache)' if cold_cache else ''}, {os.cpu_count()} cores, "
          f"median (range) of {runs} runs")
    print("| stage | wall [s] | CPU [s] | multibody simulated [s] | plant steps (10 ms) | "
          "physics at the plant's rate [s CPU] | CPU / physics | peak tree RSS [MB] |")
    print("|---|---|---|---|---|---|---|---|")
    for name in names:
        rows = [r["stages"][name] for r in results if name in r["stages"]]
        physics = rows[0]["multibody_s"] / DT * step
        ratio = [s["cpu"] / physics for s in rows] if physics > 0 else []
        print(f"| {name} | {_med([s['wall'] for s in rows])} | {_med([s['cpu'] for s in rows])} "
              f"| {rows[0]['multibody_s']:.0f} | {rows[0]['multibody_s'] / DT:.0f} | "
              f"{physics:.1f} | {_med(ratio, '{:.1f}') if ratio else '-'} | "
              f"{_med([s['rss'] / 1e6 for s in rows], '{:.0f}')} |")
    total_mb = sum(results[0]["stages"][n]["multibody_s"] for n in names)
    physics = total_mb / DT * step
    print(f"| total | {_med([r['wall'] for r in results])} | {_med([r['cpu'] for r in results])} "
          f"| {total_mb:.0f} | {total_mb / DT:.0f} | {physics:.1f} | "
          f"{_med([r['cpu'] / physics for r in results], '{:.1f}')} | "
          f"{_med([r['tree_rss'] / 1e6 for r in results], '{:.0f}')} |")
    largest = _med([r["largest_rss"] / 1e6 for r in results], "{:.0f}")
    tree = _med([r["tree_rss"] / 1e6 for r in results], "{:.0f}")
    print(f"peak memory: largest process {largest} MB; process tree {tree} MB")
    return {"campaign_wall_s": statistics.median(r["wall"] for r in results),
            "campaign_cpu_s": statistics.median(r["cpu"] for r in results),
            "plant_step_us": step * 1e6,
            "largest_rss_mb": statistics.median(r["largest_rss"] for r in results) / 1e6}


def _stages(report: Path) -> dict[str, float]:
    """The stage table of a report (its wall times) [s]."""
    out = {}
    lines = report.read_text().splitlines()
    start = lines.index("## Wall time by stage")
    for line in lines[start + 4:]:
        if not line.startswith("|"):
            break
        name, wall = (c.strip() for c in line.strip("|").split("|")[:2])
        out[name] = float(wall)
    return out


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--no-recordings", action="store_true")
    parser.add_argument("--cold-cache", action="store_true")
    parser.add_argument("--only", default="", help="a part of the campaign (its --only), to try "
                        "the benchmark quickly; the figures are the whole campaign's")
    a = parser.parse_args()
    main(a.runs, not a.no_recordings, a.cold_cache, a.only)
