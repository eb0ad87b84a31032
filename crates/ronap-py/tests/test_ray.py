"""ronap.ray on a local Ray cluster of 2 CPUs bound to 127.0.0.1: the same episodes.csv bytes and
summary figures as one `ronap run`, policies that travel as weights or pickled callables, a killed
worker's task run again without a duplicated or lost episode, a failing policy's error as ronap's
exception, a local instance (never a stale cluster) without an address, team scenarios refused
before Ray starts."""

import json
import os
import pathlib
import pickle
import shutil
import subprocess
import sys
import tempfile

import pytest
import ray
from ray.thirdparty_files import psutil  # Ray's own copy

import ronap
import ronap.ray

# Every test here shares one worker when pytest-xdist spreads the suite over the cores (scripts/test),
# with the guides' blocks that start Ray: one local Ray instance at a time.
pytestmark = pytest.mark.xdist_group("ray")

ROOT = pathlib.Path(__file__).resolve().parents[3]
TIMING = {"wall_time_s", "steps_per_second"}


@pytest.fixture(scope="module")
def cluster():
    """A local Ray instance of 2 CPUs, as `python -m ronap.ray` starts one: bound to 127.0.0.1."""
    context = ronap.ray._init(num_cpus=2)
    yield context.address_info["address"]
    ray.shutdown()


def test_the_local_instance_listens_on_127_0_0_1_only(cluster):
    assert cluster.startswith("127.0.0.1:")
    listening = [
        (p.name(), c.laddr.ip)
        for p in psutil.Process().children(recursive=True)
        for c in p.net_connections(kind="inet")
        if c.status == psutil.CONN_LISTEN
    ]
    assert listening and all(ip in ("127.0.0.1", "::ffff:127.0.0.1") for _, ip in listening), listening


def figures(run_dir):
    summary = json.loads((pathlib.Path(run_dir) / "summary.json").read_text())["summary"]
    return {k: v for k, v in summary.items() if k not in TIMING}


def ronap_run(ronap_bin, out, *args):
    r = subprocess.run([ronap_bin, "run", "--out", str(out), *args], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr


def test_blocks_write_the_bytes_of_one_run(cluster, ronap_bin, tmp_path):
    result = ronap.ray.evaluate("apf", range(5, 48), out=tmp_path / "ray", block=7)
    ronap_run(ronap_bin, tmp_path / "one", "--policy", "apf", "--seeds", "43", "--seed-start", "5")
    assert (tmp_path / "ray" / "episodes.csv").read_bytes() == (tmp_path / "one" / "episodes.csv").read_bytes()
    assert figures(tmp_path / "ray") == figures(tmp_path / "one")
    assert result["summary"]["episodes"] == 43 and "success rate" in result["table"]


def test_a_network_travels_as_its_bytes(cluster, ronap_bin, tmp_path):
    net = "mlp:policies/bc.safetensors"
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        ronap.ray.evaluate(net, range(24), out=tmp_path / "ray", block=5, maze_cols=6, maze_rows=6)
    finally:
        os.chdir(cwd)
    ronap_run(ronap_bin, tmp_path / "one", "--policy", net, "--seeds", "24", "--cols", "6", "--rows", "6")
    assert (tmp_path / "ray" / "episodes.csv").read_bytes() == (tmp_path / "one" / "episodes.csv").read_bytes()
    assert figures(tmp_path / "ray") == figures(tmp_path / "one")


def dies_once(marker, after):
    """A policy whose worker process dies the first time it has made `after` decisions (a marker
    file says it has), then behaves: a killed task, run again. Made in a function, so Ray pickles
    it by value (workers cannot import the tests)."""

    class DiesOnce:
        def __init__(self):
            self.calls = 0
            self.__name__ = "dies_once"

        def __call__(self, obs):
            self.calls += 1
            if self.calls == after and not os.path.exists(marker):
                open(marker, "w").close()
                os._exit(1)
            return 1 if obs[8] > 0.5 else 0

    return DiesOnce()


def test_a_killed_task_is_run_again_without_duplicates(cluster, tmp_path):
    policy = dies_once(str(tmp_path / "died"), after=300)
    ronap.ray.evaluate(policy, range(30), out=tmp_path / "ray", block=6, retries=2, episode_max_steps=60)
    assert (tmp_path / "died").exists(), "the worker was killed once"
    ronap.evaluate(dies_once(str(tmp_path / "died"), after=300), range(30), out=str(tmp_path / "one"), episode_max_steps=60)
    rows = (tmp_path / "ray" / "episodes.csv").read_text().splitlines()
    assert len(rows) == 31 and [r.split(",")[0] for r in rows[1:]] == [str(s) for s in range(30)]
    assert (tmp_path / "ray" / "episodes.csv").read_bytes() == (tmp_path / "one" / "episodes.csv").read_bytes()


def test_a_failing_policy_raises_ronaps_error_and_keeps_what_finished(cluster, tmp_path):
    def bad(obs):
        raise ValueError("no")

    with pytest.raises(ronap.PolicyError, match="no"):
        ronap.ray.evaluate(bad, range(10), out=tmp_path / "ray", block=5)
    assert json.loads((tmp_path / "ray" / "summary.json").read_text())["interrupted"]
    with pytest.raises(ronap.ConfigError, match="seeds is empty"):
        ronap.ray.evaluate("apf", [], out=tmp_path / "x")
    with pytest.raises(ronap.ConfigError, match="block = 0"):
        ronap.ray.evaluate("apf", range(3), block=0)


def test_errors_and_environments_pickle():
    e = pickle.loads(pickle.dumps(ronap.PolicyError("seed 3, step 4: no")))
    assert isinstance(e, ronap.PolicyError) and isinstance(e, ronap.RonapError) and "seed 3" in str(e)
    env = ronap.NavEnv(maze_cols=5)
    env.reset(seed=2)
    env.step(1)
    copy = pickle.loads(pickle.dumps(env))
    assert (copy.step(1)[0] == env.step(1)[0]).all()


def test_the_command_line(cluster, ronap_bin, tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "ronap.ray", "--policy", "random", "--seeds", "20", "--block", "6", "--out", str(tmp_path / "ray"), "--address", cluster],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert r.returncode == 0, r.stderr
    assert "success rate" in r.stdout and "20/20 episodes" in r.stderr and f"joined the Ray cluster at {cluster}" in r.stderr
    ronap_run(ronap_bin, tmp_path / "one", "--policy", "random", "--seeds", "20")
    assert (tmp_path / "ray" / "episodes.csv").read_bytes() == (tmp_path / "one" / "episodes.csv").read_bytes()
    bad = subprocess.run([sys.executable, "-m", "ronap.ray", "--policy", "nope", "--seeds", "2", "--out", str(tmp_path / "b"), "--address", cluster], capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.startswith("error") and "nope" in bad.stderr


def _files(directory):
    root = pathlib.Path(directory)
    return {p.relative_to(root): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_a_failed_run_or_resume_leaves_the_directory_as_it_was(cluster, ronap_bin, tmp_path):
    out = tmp_path / "ray"
    ronap.ray.evaluate("apf", range(10), out=out, block=5)
    before = _files(out)
    with pytest.raises(ronap.OutputError, match="force=True"):
        ronap.ray.evaluate("apf", range(10), out=out, block=5)

    def bad(obs):
        raise ValueError("no")

    # Forced over a finished run, a run whose first task fails replaces nothing.
    with pytest.raises(ronap.PolicyError, match="no"):
        ronap.ray.evaluate(bad, range(10), out=out, block=5, force=True)
    assert _files(out) == before

    # A run of a Python function stopped short, which `ronap run --resume` cannot rebuild: the
    # failed resume leaves every file (its summary.json too).
    stopped = tmp_path / "stopped"
    with pytest.raises(ronap.PolicyError, match="no"):
        ronap.ray.evaluate(bad, range(10), out=stopped, block=5)
    before = _files(stopped)
    assert "summary.json" in {p.name for p in before}
    r = subprocess.run([ronap_bin, "run", "--resume", str(stopped)], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode != 0 and "panicked" not in r.stderr, r.stderr
    assert _files(stopped) == before


def test_without_an_address_a_local_instance_starts_whatever_a_stale_file_names(ronap_bin, tmp_path):
    """Ray's temporary directory names a dead cluster (as after a crash), and RAY_ADDRESS too: the
    command starts its own instance instead of hanging on it."""
    temp = tempfile.mkdtemp(prefix="ray-", dir="/tmp")  # short: Ray's socket paths live in it
    try:
        os.makedirs(os.path.join(temp, "ray"))
        with open(os.path.join(temp, "ray", "ray_current_cluster"), "w") as f:
            f.write("127.0.0.1:1")
        env = {**os.environ, "RAY_TMPDIR": temp, "RAY_ADDRESS": "127.0.0.1:1"}
        out = tmp_path / "ray"
        r = subprocess.run(
            [sys.executable, "-m", "ronap.ray", "--policy", "apf", "--seeds", "6", "--block", "3", "--out", str(out)],
            capture_output=True,
            text=True,
            cwd=ROOT,
            env=env,
            timeout=120,
        )
        assert r.returncode == 0, r.stderr
        assert "started a local Ray instance in" in r.stderr and "6/6 episodes" in r.stderr
        assert os.listdir(os.path.join(temp, "ray")) != ["ray_current_cluster"]
    finally:
        shutil.rmtree(temp, ignore_errors=True)
    ronap_run(ronap_bin, tmp_path / "one", "--policy", "apf", "--seeds", "6")
    assert (out / "episodes.csv").read_bytes() == (tmp_path / "one" / "episodes.csv").read_bytes()


def test_a_team_scenario_is_refused_before_ray_starts(tmp_path):
    team = str(ROOT / "scenarios" / "warehouse-team.toml")
    with pytest.raises(ronap.ConfigError, match=r"a team of 8 \(\[\[robots\]\]\).*ronap.evaluate"):
        ronap.ray.evaluate("coordinated", range(4), out=tmp_path / "ray", scenario=team)
    assert not (tmp_path / "ray").exists()
    r = subprocess.run(
        [sys.executable, "-m", "ronap.ray", "--policy", "apf", "--seeds", "4", "--scenario", team, "--out", str(tmp_path / "cli")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 2 and "a team of 8" in r.stderr and not (tmp_path / "cli").exists()
    assert "Started a local Ray instance" not in r.stderr


def test_splits_and_the_held_out_warning_as_evaluate(cluster, ronap_bin, tmp_path):
    with pytest.warns(UserWarning, match="trained or chosen on"):
        ronap.ray.evaluate(f"mlp:{ROOT / 'policies' / 'dqn.safetensors'}", range(3), split="validation", out=tmp_path / "ray", block=2)
    ronap_run(ronap_bin, tmp_path / "one", "--policy", f"mlp:{ROOT / 'policies' / 'dqn.safetensors'}", "--seeds", "3", "--split", "validation")
    assert (tmp_path / "ray" / "episodes.csv").read_bytes() == (tmp_path / "one" / "episodes.csv").read_bytes()
    with pytest.raises(ronap.ConfigError, match="split"):
        ronap.ray.evaluate("apf", range(3), split="dev")
