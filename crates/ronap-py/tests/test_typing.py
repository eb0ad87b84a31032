"""The package's types as users' checkers see them: mypy --strict accepts a user script that uses
the public API, and pyright rates the package's public types at least 95% complete."""

import os
import re
import subprocess
import sys
import textwrap

USER_SCRIPT = textwrap.dedent(
    '''
    """Uses the public API as a user would."""
    import numpy as np

    import ronap
    import ronap.sb3


    def act(obs: np.ndarray) -> int:
        return int(np.argmax(obs[:17]) % 3)


    env = ronap.NavEnv(maze_cols=5)
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(act(obs))
    total: float = reward + float(info["distance"])
    done: bool = terminated or truncated

    vec = ronap.VecNavEnv(4, autoreset_mode="same_step")
    vobs, vinfo = vec.reset(seed=[0, 1, 2, 3])
    vobs, rewards, terms, truncs, vinfo = vec.step(np.ones(4, dtype=np.int64))
    mean: float = float(rewards.mean())

    result = ronap.evaluate(act, seeds=range(10), episode_max_steps=50)
    rate: float = result["summary"]["success_rate"]
    ronap.export_policy
    outputs: np.ndarray = ronap.mlp_outputs("policies/bc.safetensors", vobs)
    sb3_env = ronap.sb3.VecEnv(2)
    first = sb3_env.reset()
    print(total, done, mean, rate, outputs.shape, first)
    '''
)


def test_mypy_strict_accepts_user_code(tmp_path):
    script = tmp_path / "user.py"
    script.write_text(USER_SCRIPT)
    r = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--no-incremental", str(script)], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr


def test_pyright_verifytypes_completeness(tmp_path):
    venv_bin = os.path.dirname(sys.executable)
    env = {**os.environ, "PATH": venv_bin + os.pathsep + os.environ.get("PATH", ""), "VIRTUAL_ENV": sys.prefix}
    r = subprocess.run(
        [os.path.join(venv_bin, "pyright"), "--verifytypes", "ronap", "--ignoreexternal"], capture_output=True, text=True, cwd=tmp_path, env=env
    )
    found = re.search(r"Type completeness score: ([0-9.]+)%", r.stdout)
    assert found, r.stdout + r.stderr
    assert float(found.group(1)) >= 95.0, r.stdout
