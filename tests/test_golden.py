"""Golden outcomes: both front ends still write, byte for byte, what the code wrote before the core
was split into layers (tests/golden/README.md says which command made each file)."""

import subprocess

import pytest

import ronap

CASES = [
    ("apf", 200, "episodes-apf-0-199.csv"),
    ("geodesic", 200, "episodes-geodesic-0-199.csv"),
    ("random", 200, "episodes-random-0-199.csv"),
    ("mlp:policies/bc.safetensors", 100, "episodes-mlp-bc-0-99.csv"),
    ("mlp:policies/dqn.safetensors", 100, "episodes-mlp-dqn-0-99.csv"),
]


def _first_difference(a: bytes, b: bytes) -> str:
    for i, (x, y) in enumerate(zip(a.decode().splitlines(), b.decode().splitlines())):
        if x != y:
            return f"line {i + 1}:\n  got      {x}\n  expected {y}"
    return f"lengths differ: {len(a)} and {len(b)} bytes"


@pytest.mark.parametrize("policy, seeds, golden", CASES)
def test_cli_matches_golden(tmp_path, ronap_bin, root, policy, seeds, golden):
    subprocess.run(
        [ronap_bin, "run", "--policy", policy, "--seeds", str(seeds), "--out", str(tmp_path)],
        check=True,
        capture_output=True,
        cwd=root,
    )
    got, expected = (tmp_path / "episodes.csv").read_bytes(), (root / "tests" / "golden" / golden).read_bytes()
    assert got == expected, _first_difference(got, expected)


@pytest.mark.parametrize("policy, seeds, golden", CASES)
def test_python_matches_golden(tmp_path, root, monkeypatch, policy, seeds, golden):
    monkeypatch.chdir(root)
    ronap.evaluate(policy, range(seeds), out=str(tmp_path))
    got, expected = (tmp_path / "episodes.csv").read_bytes(), (root / "tests" / "golden" / golden).read_bytes()
    assert got == expected, _first_difference(got, expected)


def test_step_log_matches_golden(tmp_path, ronap_bin, root):
    subprocess.run(
        [ronap_bin, "run", "--policy", "apf", "--seeds", "8", "--log-steps", "--out", str(tmp_path)],
        check=True,
        capture_output=True,
    )
    got = (tmp_path / "steps" / "seed-000007.csv").read_bytes()
    expected = (root / "tests" / "golden" / "steps-apf-seed-000007.csv").read_bytes()
    assert got == expected, _first_difference(got, expected)
