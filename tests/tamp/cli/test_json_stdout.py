"""``--json``: stdout holds only the document, even where native code writes on descriptor 1
(pybullet's EGL renderer; `tamp.cli.document_only`)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
NATIVE = """
import os, sys
from tamp.cli import document_only
with document_only({enabled}):
    os.write(1, b"Loaded EGL 1.5 after reload.\\n")  # as native code does
    print('{{"document": 1}}')
print("after", flush=True)
os.write(1, b"native after\\n")
"""


def _python(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, *args], capture_output=True, text=True, env=env, timeout=timeout
    )


@pytest.mark.parametrize("enabled", [True, False])
def test_native_writes_on_stdout_go_to_stderr_while_the_document_is_made(enabled):
    done = _python("-c", NATIVE.format(enabled=enabled))
    assert done.returncode == 0, done.stderr
    if enabled:
        assert done.stdout == '{"document": 1}\nafter\nnative after\n'  # restored afterwards
        assert done.stderr == "Loaded EGL 1.5 after reload.\n"
    else:
        assert done.stdout.startswith("Loaded EGL 1.5 after reload.\n")


@pytest.mark.sim
def test_tamp_run_with_a_video_prints_only_the_json_document(tmp_path):
    argv = ["run", "--scene", "tray", "--goal", "(in a tray)", "--out", str(tmp_path), "--json"]
    done = _python("-m", "tamp.cli", *argv, timeout=300)
    assert done.returncode in (0, 1), done.stderr
    body = json.loads(done.stdout)  # the whole of stdout
    assert body["config"]["video"] is not None and (tmp_path / "report.json").is_file()
