"""The command line's error contract, shared by the CLI tests: one line on stderr, no traceback."""

from __future__ import annotations


def one_line_error(capsys, start: str = "tamp") -> str:
    """The captured stderr, asserted to be one ``error:`` line beginning with ``start``."""
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    assert err.startswith(start) and "error:" in err, err
    return err
