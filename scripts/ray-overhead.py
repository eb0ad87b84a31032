"""Ray's overhead on one machine: `ronap.ray.evaluate` of 4000 geodesic seeds (blocks of 500)
against `ronap run` of the same seeds, alternated, in one Python process, so Ray starts once (the
first call) and the later calls use the running instance, as a cluster would be used. Prints
each pair's wall times and the median ratio of the calls after the first, and checks that both
wrote the same episodes.csv.

    .venv/bin/python scripts/ray-overhead.py [RONAP_BIN] [--rounds N]
"""

import argparse
import os
import statistics
import subprocess
import tempfile
import time

import ronap.ray


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bin", nargs="?", default="target/release/ronap", help="the ronap binary")
    ap.add_argument("--rounds", type=int, default=4, help="pairs to time, the first starting Ray")
    ap.add_argument("--seeds", type=int, default=4000)
    args = ap.parse_args()
    ratios = []
    for i in range(args.rounds):
        with tempfile.TemporaryDirectory(prefix="ronap-ray-overhead-") as d:
            t = time.perf_counter()
            ronap.ray.evaluate("geodesic", range(args.seeds), block=500, out=os.path.join(d, "ray"))
            on_ray = time.perf_counter() - t
            t = time.perf_counter()
            subprocess.run(
                [args.bin, "run", "--policy", "geodesic", "--seeds", str(args.seeds), "--out", os.path.join(d, "one")],
                check=True,
                capture_output=True,
            )
            alone = time.perf_counter() - t
            with open(os.path.join(d, "ray", "episodes.csv"), "rb") as a, open(os.path.join(d, "one", "episodes.csv"), "rb") as b:
                same = a.read() == b.read()
        what = "Ray started in this call" if i == 0 else "Ray running"
        print(f"{what}: ronap.ray.evaluate {on_ray:.2f} s, ronap run {alone:.2f} s, {on_ray / alone:.2f}x, same episodes.csv: {same}")
        if i > 0:
            ratios.append(on_ray / alone)
        if not same:
            raise SystemExit("the two runs wrote different episodes.csv")
    if ratios:
        print(f"median overhead with Ray running: {statistics.median(ratios):.2f}x")


if __name__ == "__main__":
    main()
