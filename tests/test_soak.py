"""The soak test, test-sized: scripts/soak steps every built-in policy and both shipped networks
through episodes on moving seeds and checks flat memory, no hung episode and parsable outputs.
The long soak (a million episodes per policy) is `scripts/soak` with its defaults (docs/contributing.md)."""

import subprocess
import sys


def test_soak_test_sized(ronap_bin, root):
    run = subprocess.run(
        [sys.executable, str(root / "scripts" / "soak"), "--episodes", "600", "--max-steps", "60",
         "--quick", "--ronap", ronap_bin],
        capture_output=True, text=True, timeout=900,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    lines = [l for l in run.stdout.splitlines() if l.endswith("ok")]
    assert len(lines) == 6, run.stdout


def test_soak_catches_a_run_that_does_not_end(ronap_bin, root, tmp_path):
    # A run still going at the time-out is reported, not waited for.
    run = subprocess.run(
        [sys.executable, str(root / "scripts" / "soak"), "--episodes", "1000000", "--policy",
         "geodesic", "--timeout", "2", "--quick", "--ronap", ronap_bin],
        capture_output=True, text=True, timeout=120,
    )
    assert run.returncode == 1 and "did not end within 2" in run.stdout, run.stdout + run.stderr
