"""Reading PDDL and plan files: the encodings other tools save (`read_text`), and one-line
error text (`one_line`).

A file that is missing, unreadable or not text (a binary given by mistake) is one `PDDLError`
line naming the file.
"""

from __future__ import annotations

import codecs
from pathlib import Path

from task.errors import PDDLError


def read_text(path: str | Path) -> str:
    """The text of ``path``: UTF-8 (with or without a byte-order mark) or UTF-16 with its
    byte-order mark (as some Windows editors save); PDDLError naming the file if it is
    missing, unreadable or none of these (a binary file given by mistake: an image, a
    checkpoint, an archive)."""
    try:
        raw = Path(path).read_bytes()
    except FileNotFoundError:
        raise PDDLError(f"{path}: no such file") from None
    except OSError as exc:
        raise PDDLError(f"{path}: cannot read ({exc.strerror or exc})") from None
    utf16 = raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE))
    try:
        text = raw.decode("utf-16" if utf16 else "utf-8-sig")
    except UnicodeDecodeError as exc:
        raise PDDLError(
            f"{path}: not a text file (byte {exc.start} is not "
            f"{'UTF-16' if utf16 else 'UTF-8'}); expected PDDL or plan text"
        ) from None
    if "\x00" in text:  # UTF-16 without its byte-order mark decodes as UTF-8 full of NULs
        raise PDDLError(
            f"{path}: not a text file (byte {raw.index(0)} is NUL: UTF-16 without a "
            "byte-order mark?); expected PDDL or plan text in UTF-8 or UTF-16 with its mark"
        )
    return text.replace("\r\n", "\n").replace("\r", "\n")


def one_line(text: str) -> str:
    """``text`` on one line, its runs of white space made single spaces (for error messages)."""
    return " ".join(str(text).split())
