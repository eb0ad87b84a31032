"""Commands whose output goes to a pipe that closes early (`| head`) end quietly, never panic."""

import subprocess

import pytest


@pytest.mark.parametrize("args", [["bench", "--seconds", "0.2"], ["config", "--scenario"]])
def test_a_closed_pipe_ends_quietly(ronap_bin, args):
    p = subprocess.Popen([ronap_bin, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert p.stdout.readline()
    p.stdout.close()
    _, err = p.communicate(timeout=60)
    assert p.returncode == 0, err.decode()
    assert b"panicked" not in err
