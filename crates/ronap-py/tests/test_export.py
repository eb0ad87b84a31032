"""Networks from torch and Stable-Baselines3 as ronap weights files: outputs equal to torch's to
1e-5, torch.save files (zip, legacy, TorchScript) read without torch, the original RoNAP's
Softmax-ended network run, and what cannot be represented refused, naming the layer, in every
file form."""

import json
import os
import pickle
import subprocess
import sys
import pathlib
import textwrap
import warnings

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


def metadata(path):
    """The metadata of a safetensors file (its JSON header's ``__metadata__``)."""
    data = pathlib.Path(path).read_bytes()
    return json.loads(data[8 : 8 + int.from_bytes(data[:8], "little")])["__metadata__"]


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
    assert "Softmax (layer 3)" in metadata(path)["dropped"]


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
        (nn.Sequential(nn.Linear(18, 8), nn.ReLU(), nn.Linear(8, 8), nn.Tanh(), nn.Linear(8, 3)), "layer 3 is Tanh .* but layer 1 is ReLU"),
        (nn.Sequential(nn.Linear(18, 8), nn.ReLU(), nn.Linear(8, 3), nn.ReLU()), "ends with an activation .layer 3."),
        (nn.Sequential(nn.Linear(18, 8), nn.Conv1d(1, 1, 1), nn.Linear(8, 3)), "layer 1 is Conv1d"),
        (nn.Sequential(nn.Linear(18, 8), nn.Linear(8, 3)), "no activation module"),
        (nn.Sequential(nn.Linear(18, 8), nn.Softmax(dim=-1), nn.ReLU(), nn.Linear(8, 3)), "layer 1 is Softmax with layer 2 .ReLU. after it"),
        (nn.Sequential(nn.Linear(18, 8), nn.ReLU(), nn.Dropout(0.1), nn.Linear(8, 3)), "layer 2 is Dropout in training mode"),
        (PPO("MlpPolicy", ronap.NavEnv(continuous=True), device="cpu"), "Discrete"),
    ]
    for obj, message in cases:
        with pytest.raises(ronap.export.ModelError, match=message) as e:
            ronap.export_policy(obj, path)
        assert isinstance(e.value, ronap.ConfigError) and isinstance(e.value, ValueError)
        assert not path.exists()
    with pytest.raises(ronap.export.ModelError, match="activation='tanh' but layer 1 is ReLU"):
        ronap.export_policy(nn.Sequential(nn.Linear(18, 8), nn.ReLU(), nn.Linear(8, 3)), path, activation="tanh")
    # Dropout of a model in eval mode changes nothing: skipped.
    ronap.export_policy(nn.Sequential(nn.Linear(18, 8), nn.ReLU(), nn.Dropout(0.1), nn.Linear(8, 3)).eval(), path)
    path.unlink()
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
    # A missing file is ronap's error and a FileNotFoundError naming the file; bad values are
    # ValueErrors too. Both pickle by name.
    with pytest.raises(FileNotFoundError) as missing:
        ronap.import_torch(tmp_path / "nowhere.pt", path)
    assert isinstance(missing.value, ronap.ConfigError) and missing.value.filename == str(tmp_path / "nowhere.pt")
    assert missing.value.errno == 2 and str(missing.value).startswith("[Errno 2] import_torch: no such file")
    copy = pickle.loads(pickle.dumps(missing.value))
    assert type(copy) is ronap.export.MissingFileError and copy.filename == missing.value.filename
    # Still so once ConfigError is also a ValueError (as issue 47 asks of it).
    check = (
        "import ronap; ronap.ConfigError.__bases__ = (ronap.RonapError, ValueError)\n"
        "e = ronap.export.MissingFileError(2, 'no such file', 'f.pt')\n"
        "assert (e.errno, e.filename, str(e)) == (2, 'f.pt', \"[Errno 2] no such file: 'f.pt'\"), (e.errno, e.filename, str(e))"
    )
    r = subprocess.run([sys.executable, "-c", check], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with pytest.raises(ValueError, match="bad.pt"):
        ronap.import_torch(bad, path)
    assert not path.exists()


@pytest.mark.parametrize("final", [nn.Softmax, nn.LogSoftmax])
@pytest.mark.parametrize("zip_format", [True, False], ids=["zip", "legacy"])
def test_the_original_ronaps_softmax_ended_network_runs(tmp_path, ronap_bin, final, zip_format):
    """The original RoNAP's `model_net.pkl`: a legacy torch.save of a whole `nn.Sequential` of
    Linear layers and activations ending in Softmax (saved in training mode, as it was)."""
    torch.manual_seed(4)
    net = nn.Sequential(nn.Linear(18, 64), nn.ReLU(), nn.Linear(64, 128), nn.ReLU(), nn.Linear(128, 3), final(dim=1))
    saved = tmp_path / "model_net.pkl"
    torch.save(net, saved, _use_new_zipfile_serialization=zip_format)
    out = tmp_path / "net.safetensors"
    ronap.import_torch(saved, out)
    obs = observations(n=1000, seed=5)
    ours, theirs = ronap.mlp_outputs(out, obs), torch_outputs(net.eval(), obs)
    assert (ours.argmax(1) == theirs.argmax(1)).all()
    assert np.allclose(ours, torch_outputs(net[:5], obs), atol=1e-5)  # the logits before the Softmax
    assert f"{final.__name__} (layer 5)" in metadata(out)["dropped"]
    run = subprocess.run([ronap_bin, "run", "--policy", f"mlp:{out}", "--seeds", "3", "--max-steps", "50"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def torchscript(module, path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)  # torch.jit is deprecated, files still exist
        torch.jit.save(torch.jit.script(module), path)


def file_forms(net, directory):
    """`net` saved in every form import_torch reads: {form: path}."""
    forms = {}
    for zip_format, name in [(True, "zip"), (False, "legacy")]:
        forms[f"whole {name}"] = directory / f"whole-{name}.pt"
        torch.save(net, forms[f"whole {name}"], _use_new_zipfile_serialization=zip_format)
        forms[f"state_dict {name}"] = directory / f"sd-{name}.pt"
        torch.save(net.state_dict(), forms[f"state_dict {name}"], _use_new_zipfile_serialization=zip_format)
    forms["torchscript"] = directory / "script.pt"
    torchscript(net, forms["torchscript"])
    return forms


# Networks ronap cannot represent, with what the refusal says of the layer: as a whole module
# (pickled or TorchScript), and as a state_dict (None: its keys cannot show it).
REFUSED = {
    "LayerNorm": (
        lambda: nn.Sequential(nn.Linear(18, 16), nn.LayerNorm(16), nn.ReLU(), nn.Linear(16, 3)),
        "layer 1 is LayerNorm",
        r"layer 1 is a normalisation layer such as LayerNorm \(1.weight is 1-D\)",
    ),
    "BatchNorm": (
        lambda: nn.Sequential(nn.Linear(18, 16), nn.BatchNorm1d(16), nn.ReLU(), nn.Linear(16, 3)),
        "layer 1 is BatchNorm1d",
        r"layer 1 is a BatchNorm \(1.running_mean\)",
    ),
    "Conv1d": (
        lambda: nn.Sequential(nn.Linear(18, 16), nn.ReLU(), nn.Conv1d(1, 1, 3), nn.Linear(16, 3)),
        "layer 2 is Conv1d",
        r"layer 2 is a Conv1d \(2.weight is 3-D\)",
    ),
    "mixed activations": (
        lambda: nn.Sequential(nn.Linear(18, 16), nn.ReLU(), nn.Linear(16, 16), nn.Tanh(), nn.Linear(16, 3)),
        r"layer 3 is Tanh \(tanh\) but layer 1 is ReLU \(relu\)",
        None,
    ),
    "Dropout in training mode": (
        lambda: nn.Sequential(nn.Linear(18, 16), nn.ReLU(), nn.Dropout(0.2), nn.Linear(16, 3)),
        "layer 2 is Dropout in training mode",
        None,
    ),
}


@pytest.mark.parametrize("case", list(REFUSED))
def test_what_cannot_be_represented_is_refused_naming_the_layer_in_every_file_form(tmp_path, case):
    make, whole, state_dict = REFUSED[case]
    torch.manual_seed(6)
    net = make()
    if case == "Dropout in training mode":
        net.train()
    else:
        net.eval()
    out = tmp_path / "net.safetensors"
    for form, saved in file_forms(net, tmp_path).items():
        message = whole if not form.startswith("state_dict") else state_dict
        if message is None:
            # A state_dict holds no activations and no dropout: the caller vouches for the
            # activation, and without one it is asked for.
            with pytest.raises(ronap.export.ModelError, match="give activation='relu'"):
                ronap.import_torch(saved, out)
            continue
        with pytest.raises(ronap.export.ModelError, match=message) as e:
            ronap.import_torch(saved, out, activation="relu")
        assert isinstance(e.value, ValueError) and str(saved) in str(e.value), form
        assert not out.exists(), form


def test_a_modules_own_code_and_keys_that_are_no_linear_layer_are_refused(tmp_path):
    class Net(nn.Module):
        """The original RoNAP's way: layers as attributes, a softmax among them."""

        def __init__(self, ln=False, scale=False):
            super().__init__()
            self.fc1, self.fc2 = nn.Linear(18, 32), nn.Linear(32, 3)
            self.act, self.softmax = nn.RReLU(), nn.Softmax(dim=-1)
            self.ln = nn.LayerNorm(32) if ln else None
            self.scale = nn.Parameter(torch.ones(18)) if scale else None

        def forward(self, x):
            x = x * self.scale if self.scale is not None else x
            x = self.act(self.fc1(x))
            return self.softmax(self.fc2(self.ln(x) if self.ln is not None else x))

    torch.manual_seed(7)
    out = tmp_path / "net.safetensors"
    # Whole modules pickle by reference to their class: save them with the class importable.
    good = Net().eval()
    ronap.export_policy(good, out)
    obs = observations(n=1000, seed=8)
    assert (ronap.mlp_outputs(out, obs).argmax(1) == torch_outputs(good, obs).argmax(1)).all()
    assert "Softmax (layer softmax)" in metadata(out)["dropped"]
    out.unlink()
    with pytest.raises(ronap.export.ModelError, match="layer ln is LayerNorm"):
        ronap.export_policy(Net(ln=True), out)
    with pytest.raises(ronap.export.ModelError, match="scale: a tensor Net uses in its own code"):
        ronap.export_policy(Net(scale=True), out)
    torchscript(Net(ln=True).eval(), tmp_path / "ln-script.pt")
    with pytest.raises(ronap.export.ModelError, match="layer ln is LayerNorm"):
        ronap.import_torch(tmp_path / "ln-script.pt", out)
    cases = {
        "ln": (Net(ln=True).state_dict(), r"layer ln is a normalisation layer such as LayerNorm \(ln.weight is 1-D\)"),
        "scale": (Net(scale=True).state_dict(), "scale: not a Linear layer's weight or bias"),
        "chain": ({"a.weight": torch.ones(8, 18), "b.weight": torch.ones(3, 9)}, "b.weight takes 9 inputs but a.weight gives 8 outputs"),
        "log_std": ({**Net().state_dict(), "log_std": torch.zeros(3)}, "log_std: not a Linear layer's weight or bias"),
        "checkpoint": ({"epoch": 3, "weights": Net().state_dict()}, "epoch = 3 is not a tensor: not a state_dict"),
    }
    for name, (state, message) in cases.items():
        torch.save(state, tmp_path / f"{name}.pt")
        with pytest.raises(ronap.export.ModelError, match=message):
            ronap.import_torch(tmp_path / f"{name}.pt", out, activation="rrelu")
        assert not out.exists(), name
    # A state_dict of the good network, with the activation its caller vouches for.
    torch.save(good.state_dict(), tmp_path / "good.pt")
    ronap.import_torch(tmp_path / "good.pt", out, activation="rrelu")
    assert np.allclose(ronap.mlp_outputs(out, obs), torch_outputs(nn.Sequential(good.fc1, good.act, good.fc2), obs), atol=1e-5)
    assert "caller" in metadata(out)["activation_from"]


def test_torchscript_files_are_read_without_torch(tmp_path):
    torch.manual_seed(9)
    net = nn.Sequential(nn.Linear(18, 32), nn.Tanh(), nn.Linear(32, 3), nn.Softmax(dim=-1)).eval()
    torchscript(net, tmp_path / "script.pt")
    out = tmp_path / "net.safetensors"
    r = subprocess.run([sys.executable, "-c", READ_WITHOUT_TORCH, str(tmp_path / "script.pt"), str(out)], capture_output=True, text=True, cwd="/")
    assert r.returncode == 0, r.stderr
    obs = observations(n=1000, seed=10)
    assert np.allclose(ronap.mlp_outputs(out, obs), torch_outputs(net[:3], obs), atol=1e-5)
    assert "TorchScript" in metadata(out)["trained"]
    # A slope compiled into the code is not in the file: refused, naming the layer.
    torchscript(nn.Sequential(nn.Linear(18, 8), nn.LeakyReLU(0.2), nn.Linear(8, 3)), tmp_path / "leaky.pt")
    with pytest.raises(ronap.export.ModelError, match="layer 1 .LeakyReLU.: its slope is compiled into TorchScript code"):
        ronap.import_torch(tmp_path / "leaky.pt", out)
