"""Python policies in a team run (`ronap run --scenario` with `[[robots]]` and `py:FILE:FUNC`): a
function of two arguments hears what its robot received and answers with an action and a message,
which reaches the robots within range one step later."""

import json
import pathlib
import subprocess

TALKER = '''
import json, os, pathlib
n = 0
def act(obs, inbox):
    global n
    n += 1
    heard = [{"from": m["from"], "message": [float(x) for x in m["message"]]} for m in inbox]
    log = pathlib.Path(__file__).parent / f"heard-{os.getpid()}.jsonl"
    with open(log, "a") as f:
        f.write(json.dumps({"n": n, "obs": [float(x) for x in obs[-3:]], "heard": heard}) + "\\n")
    return 0, [float(n), 7.0]

def lone(obs):
    return 1

def bad_message(obs, inbox):
    return 1, ["x"]
'''

SCENARIO = '''
[scene]
kind = "maze"
seed = 0

[maze]
cols = 30
rows = 1
cell_px = 18.0

[episode]
max_steps = 5
min_goal_distance_px = 10.0

[team]
message_size = 2
neighbours = 1
comm_range_px = {range}

[[robots]]
start = [15.0, 9.0, 0.0]
goal = [525.0, 9.0]

[[robots]]
start = [100.0, 9.0, 180.0]
goal = [15.0, 9.0]
'''


def run(ronap_bin, tmp_path, function, comm_range, name):
    policy = tmp_path / "talk.py"
    policy.write_text(TALKER)
    scenario = tmp_path / f"{name}.toml"
    scenario.write_text(SCENARIO.replace("{range}", str(comm_range)))
    return subprocess.run(
        [ronap_bin, "run", "--scenario", str(scenario), "--policy", f"py:{policy}:{function}", "--seeds", "1",
         "--threads", "1", "--out", str(tmp_path / name)],
        capture_output=True,
        text=True,
    )


def logs(tmp_path):
    return [[json.loads(line) for line in p.read_text().splitlines()] for p in sorted(tmp_path.glob("heard-*.jsonl"))]


def test_messages_reach_python_policies_a_step_late_within_range(ronap_bin, tmp_path):
    r = run(ronap_bin, tmp_path, "act", 200.0, "near")
    assert r.returncode == 0, r.stderr
    per_robot = [log for log in logs(tmp_path) if len(log) == 5]
    assert len(per_robot) == 2, logs(tmp_path)
    for log in per_robot:
        # Nothing heard before the first step; then the other robot's message of the step before.
        assert log[0]["heard"] == []
        for entry in log[1:]:
            assert len(entry["heard"]) == 1
            assert entry["heard"][0]["message"] == [entry["n"] - 1.0, 7.0]
            # The observation's neighbour slot carries it too (present flag, then the message).
            assert entry["obs"] == [1.0, entry["n"] - 1.0, 7.0]
    assert {log[1]["heard"][0]["from"] for log in per_robot} == {0, 1}


def test_out_of_range_robots_hear_nothing(ronap_bin, tmp_path):
    r = run(ronap_bin, tmp_path, "act", 50.0, "far")
    assert r.returncode == 0, r.stderr
    for log in logs(tmp_path):
        assert all(entry["heard"] == [] for entry in log)


def test_one_argument_functions_still_work_and_bad_messages_are_named(ronap_bin, tmp_path):
    assert run(ronap_bin, tmp_path, "lone", 200.0, "lone").returncode == 0
    r = run(ronap_bin, tmp_path, "bad_message", 200.0, "bad")
    assert r.returncode != 0
    assert "returned the message" in r.stderr and "'x'" in r.stderr, r.stderr
