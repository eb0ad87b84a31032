"""The documentation's commands and references against the code.

- Every fenced block marked for it in README.md and docs/ runs, on small seed counts: a line
  ``<!-- doctest -->`` just before a ```` ```sh ```` or ```` ```python ```` block. Shell blocks run
  in bash with ``ronap`` on the PATH resolving to $RONAP_BIN, Python blocks in this interpreter
  (with the ``ronap`` module installed). The blocks of one page run in order in one temporary
  directory holding copies of ``scenarios/``, ``policies/`` and ``examples/``, so a page's later commands may use
  what its earlier ones wrote. Large counts are cut before running (``--seeds 1000`` runs as
  ``--seeds 3``, ``seeds=range(1000)`` as ``seeds=range(3)``, and so on: see ``SMALLER``); the page shows the
  command a user runs.
- ``docs/reference/python.md`` is generated from the module's signatures and docstrings and must
  equal the committed file (``RONAP_UPDATE_DOCS=1`` rewrites it).
"""

import inspect
import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
MARK = "<!-- doctest -->"

# (pattern, largest value kept as it is, value a larger one is cut to).
SMALLER = [
    (r"(--seeds[ =])(\d+)", 20, 3),
    (r"(--samples[ =])(\d+)", 400, 400),
    (r"(--per-episode[ =])(\d+)", 200, 200),
    (r"(--epochs[ =])(\d+)", 1, 1),
    (r"(--steps[ =])(\d+)", 1000, 1000),
    (r"(--eval-every[ =])(\d+)", 500, 500),
    (r"(--eval-seeds[ =])(\d+)", 2, 2),
    (r"(--episodes[ =])(\d+)", 3, 3),
    (r"(seeds=range\()(\d+)", 20, 3),
    (r"(total_timesteps=)(\d+)", 256, 256),
]


def smaller(code: str) -> str:
    """``code`` with its large counts cut (SMALLER)."""
    for pattern, keep, cut in SMALLER:
        code = re.sub(pattern, lambda m: m.group(1) + (m.group(2) if int(m.group(2)) <= keep else str(cut)), code, flags=re.M)
    return code


def marked_blocks(page: pathlib.Path) -> list[tuple[int, str, str]]:
    """The blocks marked for running in ``page``: (line, language, code)."""
    blocks = []
    lines = page.read_text().splitlines()
    i = 0
    while i < len(lines):
        if lines[i].strip() == MARK and i + 1 < len(lines):
            fence = lines[i + 1].strip()
            language = fence.lstrip("`").strip()
            assert fence.startswith("```") and language in ("sh", "python"), (
                f"{page}:{i + 1}: {MARK} must be followed by a ```sh or ```python block"
            )
            end = i + 2
            while end < len(lines) and lines[end].strip() != "```":
                end += 1
            blocks.append((i + 2, language, "\n".join(lines[i + 2 : end])))
            i = end
        i += 1
    return blocks


PAGES = sorted([ROOT / "README.md", *(ROOT / "docs").rglob("*.md")])
MARKED = [p for p in PAGES if marked_blocks(p)]


def test_some_pages_have_marked_blocks():
    assert len(MARKED) >= 5, [str(p) for p in MARKED]


def with_group(page):
    """A page whose blocks start a local Ray instance runs in the worker that runs tests/test_ray.py
    (scripts/test runs pytest on both cores with pytest-xdist): one local Ray instance at a time."""
    if "ronap.ray" in page.read_text():
        return pytest.param(page, marks=pytest.mark.xdist_group("ray"))
    return page


@pytest.mark.parametrize("page", [with_group(p) for p in MARKED], ids=lambda p: str(p.relative_to(ROOT)))
def test_marked_blocks_run(page, tmp_path, ronap_bin):
    for folder in ("scenarios", "policies", "examples"):
        shutil.copytree(ROOT / folder, tmp_path / folder)
    bin_dir = tmp_path / ".bin"
    bin_dir.mkdir()
    (bin_dir / "ronap").symlink_to(ronap_bin)
    # A script, not a link: a virtualenv's interpreter finds its packages from its own path.
    (bin_dir / "python").write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    (bin_dir / "python").chmod(0o755)
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}", RONAP_PYTHON=sys.executable)
    for line, language, code in marked_blocks(page):
        code = smaller(code)
        if language == "sh":
            command = ["bash", "-euo", "pipefail", "-c", code]
        else:
            command = [sys.executable, "-c", code]
        done = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, (
            f"{page.relative_to(ROOT)}:{line}: the block exited {done.returncode}\n--- block (as run)\n{code}\n"
            f"--- stdout\n{done.stdout[-3000:]}\n--- stderr\n{done.stderr[-3000:]}"
        )


def test_smaller_cuts_counts():
    assert smaller("ronap run --seeds 1000 --png 5") == "ronap run --seeds 3 --png 5"
    assert smaller("ronap.evaluate(p, seeds=range(1000))") == "ronap.evaluate(p, seeds=range(3))"
    assert smaller("--seeds 8 --gif 7") == "--seeds 8 --gif 7"


# The Python reference: what `import ronap` offers, with signatures and docstrings.
PYTHON_MD = ROOT / "docs" / "reference" / "python.md"


def _entry(name: str, obj: object) -> str:
    try:
        signature = str(inspect.signature(obj))  # type: ignore[arg-type]
    except (TypeError, ValueError):
        signature = ""
    kind = "class" if inspect.isclass(obj) else "function" if callable(obj) else "value"
    heading = f"### `{name}{signature if kind != 'value' else ''}`"
    doc = inspect.getdoc(obj) or ""
    if kind == "value":
        doc = f"`{obj!r}`"
    out = [heading, "", doc.strip(), ""]
    if inspect.isclass(obj) and not issubclass(obj, BaseException):
        for member, value in sorted(vars(obj).items()):
            if member.startswith("_") or not callable(value) and not isinstance(value, property):
                continue
            target = value.fget if isinstance(value, property) else value
            try:
                sig = "" if isinstance(value, property) else str(inspect.signature(target))
            except (TypeError, ValueError):
                sig = "(...)"
            first = (inspect.getdoc(target) or "").strip()
            out.append(f"- `{member}{sig}`" + (f": {first}" if first else ""))
        out.append("")
    return "\n".join(out).replace("\n\n\n", "\n\n")


def python_reference() -> str:
    import ronap
    import ronap.ray
    import ronap.sb3

    parts = [
        "# Python reference",
        "",
        "<!-- Generated from the module's signatures and docstrings by tests/test_docs.py; do not",
        "edit by hand. Regenerate: RONAP_UPDATE_DOCS=1 .venv/bin/pytest tests/test_docs.py -k python -->",
        "",
        "The `ronap` module (`pip install ./crates/ronap-py`), as `import ronap` gives it, then",
        "`ronap.sb3` (Stable-Baselines3) and `ronap.ray` (Ray). Configuration keywords are the",
        "fields of [config.md](config.md) as `section_field=value` (`maze_cols=5`), or",
        "`config={\"maze\": {\"cols\": 5}}`; `scenario=` takes a scenario file or the same structure",
        "as a dict. The guide is [../guides/python-and-rl.md](../guides/python-and-rl.md).",
        "",
        "## `ronap`",
        "",
        (inspect.getdoc(ronap) or "").strip(),
        "",
    ]
    for name in ronap.__all__:
        parts.append(_entry(f"ronap.{name}", getattr(ronap, name)))
    for module, names in ((ronap.sb3, ["VecEnv"]), (ronap.ray, ["evaluate"])):
        parts += [f"## `{module.__name__}`", "", (inspect.getdoc(module) or "").strip(), ""]
        for name in names:
            parts.append(_entry(f"{module.__name__}.{name}", getattr(module, name)))
    text = "\n".join(parts)
    text = re.sub(r"\n{3,}", "\n\n", text).strip() + "\n"
    # Addresses of objects differ between runs.
    return re.sub(r" at 0x[0-9a-f]+", "", text)


def test_python_reference_matches_the_module():
    generated = python_reference()
    committed = PYTHON_MD.read_text() if PYTHON_MD.exists() else ""
    if generated != committed and os.environ.get("RONAP_UPDATE_DOCS"):
        PYTHON_MD.write_text(generated)
        return
    assert generated == committed, (
        "docs/reference/python.md is out of date with the module; regenerate it with\n"
        "  RONAP_UPDATE_DOCS=1 .venv/bin/pytest tests/test_docs.py -k python"
    )
