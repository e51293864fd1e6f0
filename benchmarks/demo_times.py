"""The main demo's whole command, timed as a user runs it (issue 20: the
2 x 2 plain weave of 7-fibre bundles, 2 and 1.5 yarn widths apart, <= 30 s
on 2 cores).

    python3 benchmarks/demo_times.py [--repeat 3] [--ranks 2]

Runs ``mpirun -n RANKS python demos/demo_plain_weave.py`` (2 widths apart)
and ``... --spacing 1.5 --amplitude 0.45``, each ``--repeat`` times, one at
a time, and prints per run: the whole command's wall time, the solver's
(the last step's running total), the pictures' (results.json meta),
Newton iterations of the accepted steps and failed attempts (results.json steps). Writes
``benchmarks/output/demo_times.json`` (its runs added with the date and
machine). The VM's speed varies between runs; a row is one run.
"""
import argparse
import datetime
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "benchmarks", "output")
CASES = {"2 widths": [], "1.5 widths": ["--spacing", "1.5", "--amplitude", "0.45"]}


def run_demo(args: list[str], ranks: int) -> dict:
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               MPLBACKEND="Agg")
    with tempfile.TemporaryDirectory(prefix="demo_times_") as tmp:
        command = ["mpirun", "-n", str(ranks), sys.executable,
                   os.path.join(ROOT, "demos", "demo_plain_weave.py"), "--output", tmp, *args]
        start = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=ROOT)
        wall = time.perf_counter() - start
        log = done.stdout + done.stderr
        if done.returncode != 0:
            raise SystemExit(f"{' '.join(command)} failed ({done.returncode}):\n{log[-3000:]}")
        totals = re.findall(r"\(total ([0-9.]+) s\)", log)
        with open(os.path.join(tmp, "results.json")) as f:
            results = json.load(f)
    steps = results["steps"]
    pictures = results["meta"].get("pictures", {})
    return dict(wall_seconds=round(wall, 2),
                solving_seconds=float(totals[-1]) if totals else None,
                picture_seconds=round(max((p["seconds"] for p in pictures.values()),
                                          default=0.0), 2),
                newton_iterations_accepted=sum(s["newton_iterations"] for s in steps),
                failed_attempts=sum(s["attempts"] - 1 for s in steps),
                steps=len(steps), woven="every crossing follows the pattern" in log)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--ranks", type=int, default=2)
    args = parser.parse_args()
    rows = []
    print(f"{'case':<11} {'wall [s]':>8} {'solving':>8} {'pictures':>8} {'Newton':>6} "
          f"{'failed':>6}")
    for name, extra in CASES.items():
        for _ in range(args.repeat):
            r = dict(case=name, ranks=args.ranks, **run_demo(extra, args.ranks))
            rows.append(r)
            print(f"{name:<11} {r['wall_seconds']:8.1f} {r['solving_seconds']:8.1f} "
                  f"{r['picture_seconds']:8.1f} {r['newton_iterations_accepted']:6d} "
                  f"{r['failed_attempts']:6d}" + ("" if r["woven"] else "  NOT WOVEN"),
                  flush=True)
    os.makedirs(OUT, exist_ok=True)
    path = os.path.join(OUT, "demo_times.json")
    old = json.load(open(path)) if os.path.exists(path) else []
    stamp = dict(date=datetime.datetime.now().isoformat(timespec="seconds"),
                 machine=f"{platform.node()} {os.cpu_count()} cores")
    with open(path, "w") as f:
        json.dump(old + [dict(stamp, **r) for r in rows], f, indent=1)
    print(f"written {path}")


if __name__ == "__main__":
    main()
