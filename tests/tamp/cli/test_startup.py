"""The command line starts light: ``tamp --help``, ``tamp --version`` and usage errors never
import torch, a simulator or the PDDL machinery (they ran 3.5-4.8 s when the parser imported
torch; the whole-process times are in BENCHMARKS.md, not asserted here)."""

from __future__ import annotations

import subprocess
import sys

import pytest

HEAVY = ("torch", "pybullet", "mujoco", "pytorch_kinematics", "ruckig", "pddl")

PROBE = """
import sys
from tamp.cli import main
code = main({argv!r})
heavy = sorted(m for m in {heavy!r} if m in sys.modules)
print("HEAVY", ",".join(heavy))
"""


@pytest.mark.parametrize(
    "argv",
    [["--help"], ["--version"], ["plan", "--bogus"], ["bench", "motion", "--help"], []],
)
def test_parser_paths_import_nothing_heavy(argv):
    code = PROBE.format(argv=argv, heavy=HEAVY)
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60
    ).stdout
    assert "HEAVY \n" in out or out.rstrip().endswith("HEAVY"), out


def test_version_names_the_distribution(capsys):
    from tamp.cli import main

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.startswith("tamp 0.")
