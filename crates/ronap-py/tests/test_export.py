"""Networks from torch and Stable-Baselines3 as ronap weights files: outputs equal to torch's to
1e-5, torch.save files (zip and legacy) read without torch, and what cannot be exported refused."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import torch
from torch import nn

import ronap


def observations(n=200, d=18, seed=0):
    return np.random.default_rng(seed).uniform(0, 1, (n, d)).astype(np.float32)


def torch_outputs(module, obs):
    with torch.no_grad():
        return module(torch.from_numpy(obs)).numpy()


def test_sequential_outputs_equal_torchs(tmp_path):
    torch.manual_seed(0)
    for act, name in [(nn.ReLU, "relu"), (nn.Tanh, "tanh"), (lambda: nn.LeakyReLU(0.2), "leaky_relu:0.2")]:
        net = nn.Sequential(nn.Linear(18, 64), act(), nn.Linear(64, 32), act(), nn.Linear(32, 3)).eval()
        path = tmp_path / "net.safetensors"
        ronap.export_policy(net, path)
        obs = observations()
        assert np.allclose(ronap.mlp_outputs(path, obs), torch_outputs(net, obs), atol=1e-5), name


def test_rrelu_at_inference_and_a_final_softmax(tmp_path):
    torch.manual_seed(1)
    net = nn.Sequential(nn.Linear(18, 16), nn.RReLU(), nn.Linear(16, 3), nn.Softmax(dim=-1)).eval()
    path = tmp_path / "net.safetensors"
    ronap.export_policy(net, path)
    obs = observations()
    # Softmax keeps the order: same greedy actions.
    assert (ronap.mlp_outputs(path, obs).argmax(1) == torch_outputs(net, obs).argmax(1)).all()
    assert np.allclose(ronap.mlp_outputs(path, obs), torch_outputs(net[:3], obs), atol=1e-5)


def test_sb3_ppo_and_dqn_export_their_greedy_policies(tmp_path, ronap_bin):
    from stable_baselines3 import DQN, PPO

    env = ronap.NavEnv()
    obs = observations()
    ppo = PPO("MlpPolicy", env, seed=0, device="cpu")
    path = tmp_path / "ppo.safetensors"
    ronap.export_policy(ppo, path)
    with torch.no_grad():
        logits = ppo.policy.action_net(ppo.policy.mlp_extractor.forward_actor(torch.from_numpy(obs))).numpy()
    out = ronap.mlp_outputs(path, obs)
    assert np.allclose(out, logits, atol=1e-5)
    assert (out.argmax(1) == ppo.predict(obs, deterministic=True)[0]).all()

    dqn = DQN("MlpPolicy", env, seed=0, device="cpu", learning_starts=0)
    qpath = tmp_path / "dqn.safetensors"
    ronap.export_policy(dqn, qpath)
    with torch.no_grad():
        q = dqn.q_net(torch.from_numpy(obs)).numpy()
    assert np.allclose(ronap.mlp_outputs(qpath, obs), q, atol=1e-5)

    # The exported file runs in the Rust evaluator: the same episodes as SB3's own predict().
    seeds = range(12)
    rust = ronap.evaluate(f"mlp:{path}", seeds, episode_max_steps=150)
    py = ronap.evaluate(lambda o: ppo.predict(o, deterministic=True)[0], seeds, batch=12, episode_max_steps=150)
    assert [(e["outcome"], e["steps"]) for e in rust["episodes"]] == [(e["outcome"], e["steps"]) for e in py["episodes"]]
    run = subprocess.run([ronap_bin, "run", "--policy", f"mlp:{path}", "--seeds", "3", "--max-steps", "50"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def test_what_cannot_be_exported_is_refused(tmp_path):
    from stable_baselines3 import PPO

    path = tmp_path / "x.safetensors"
    cases = [
        (nn.Sequential(nn.Linear(18, 8), nn.ReLU(), nn.Linear(8, 2)), "needs 3"),
        (nn.Sequential(nn.Linear(18, 8), nn.ReLU(), nn.Linear(8, 8), nn.Tanh(), nn.Linear(8, 3)), "several activations"),
        (nn.Sequential(nn.Linear(18, 8), nn.ReLU(), nn.Linear(8, 3), nn.ReLU()), "ends with an activation"),
        (nn.Sequential(nn.Linear(18, 8), nn.Conv1d(1, 1, 1), nn.Linear(8, 3)), "module 1 is Conv1d"),
        (nn.Sequential(nn.Linear(18, 8), nn.Linear(8, 3)), "no activation module"),
        (PPO("MlpPolicy", ronap.NavEnv(continuous=True), device="cpu"), "Discrete"),
    ]
    for obj, message in cases:
        with pytest.raises(ronap.ConfigError, match=message):
            ronap.export_policy(obj, path)
        assert not path.exists()
    # The activation named where the module applies it in code.
    ronap.export_policy(nn.Sequential(nn.Linear(18, 8), nn.Linear(8, 3)), path, activation="tanh")
    assert path.exists()


MODEL = textwrap.dedent(
    """
    import torch
    from torch import nn

    class Net(nn.Module):
        # Like the original RoNAP's network: layers as attributes, one activation module.
        def __init__(self):
            super().__init__()
            self.fc1 = nn.Linear(18, 64)
            self.fc2 = nn.Linear(64, 128)
            self.fc3 = nn.Linear(128, 3)
            self.act = nn.RReLU()

        def forward(self, x):
            return self.fc3(self.act(self.fc2(self.act(self.fc1(x)))))
    """
)

READ_WITHOUT_TORCH = textwrap.dedent(
    """
    import sys
    sys.modules["torch"] = None  # any import of torch now fails
    import ronap
    ronap.import_torch(sys.argv[1], sys.argv[2], **({"activation": sys.argv[3]} if len(sys.argv) > 3 else {}))
    """
)


@pytest.mark.parametrize("zip_format", [True, False], ids=["zip", "legacy"])
def test_torch_files_read_without_torch_or_the_models_code(tmp_path, zip_format):
    (tmp_path / "ronap_test_net.py").write_text(MODEL)
    sys.path.insert(0, str(tmp_path))
    try:
        import ronap_test_net

        torch.manual_seed(2)
        net = ronap_test_net.Net().eval()
        files = {
            "whole": net,
            "state_dict": net.state_dict(),
            "checkpoint": {"epoch": 3, "model_state_dict": net.state_dict()},
        }
        obs = observations(seed=3)
        for name, obj in files.items():
            saved = tmp_path / f"{name}.pt"
            torch.save(obj, saved, _use_new_zipfile_serialization=zip_format)
            if not zip_format:
                assert saved.read_bytes()[:2] == b"\x80\x02"  # a pickle, not a zip
            out = tmp_path / f"{name}.safetensors"
            extra = [] if name == "whole" else ["rrelu"]
            # A fresh interpreter with torch blocked and the model's module not on the path.
            r = subprocess.run([sys.executable, "-c", READ_WITHOUT_TORCH, str(saved), str(out), *extra], capture_output=True, text=True, cwd="/")
            assert r.returncode == 0, (name, r.stderr)
            assert np.allclose(ronap.mlp_outputs(out, obs), torch_outputs(net, obs), atol=1e-5), name
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("ronap_test_net", None)


def test_bad_torch_files_are_config_errors(tmp_path):
    path = tmp_path / "x.safetensors"
    bad = tmp_path / "bad.pt"
    bad.write_bytes(b"not a torch file")
    with pytest.raises(ronap.ConfigError, match="bad.pt"):
        ronap.import_torch(bad, path)
    good = tmp_path / "good.pt"
    torch.save(nn.Sequential(nn.Linear(18, 4), nn.ReLU(), nn.Linear(4, 3)), good, _use_new_zipfile_serialization=False)
    cut = tmp_path / "cut.pt"
    cut.write_bytes(good.read_bytes()[:-50])
    with pytest.raises(ronap.ConfigError, match="cut.pt"):
        ronap.import_torch(cut, path)
    sd = tmp_path / "sd.pt"
    torch.save(nn.Sequential(nn.Linear(18, 4), nn.ReLU(), nn.Linear(4, 3)).state_dict(), sd)
    with pytest.raises(ronap.ConfigError, match="activation='relu'"):
        ronap.import_torch(sd, path)
    assert not path.exists()
    # A pickle that would run code if torch.load read it is only a stand-in here.
    evil = tmp_path / "evil.pt"
    evil.write_bytes(b"\x80\x02cos\nsystem\nq\x00X\x04\x00\x00\x00trueq\x01\x85q\x02Rq\x03.")
    with pytest.raises(ronap.ConfigError):
        ronap.import_torch(evil, path)
