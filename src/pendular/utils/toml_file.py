"""Reading a TOML file the user names (campaign tables, loading-path tables), with one error
line for each way it can be unreadable."""

from __future__ import annotations

import os
import stat


def read_toml(path: str | os.PathLike, source: str) -> dict:
    """The TOML file at ``path`` as a dict; ValueError starting with ``source`` (how the
    message names the file) when it cannot be read, is not a regular file (a device or a pipe
    may never end), is not UTF-8 (with the line and column) or not valid TOML."""
    try:
        import tomllib
    except ModuleNotFoundError:        # Python 3.10
        import tomli as tomllib
    try:
        regular = stat.S_ISREG(os.stat(path).st_mode)
        if regular:
            with open(path, "rb") as handle:
                data = handle.read()
    except (OSError, ValueError) as error:
        raise ValueError(f"{source} cannot be read: "
                         f"{getattr(error, 'strerror', None) or error}") from None
    if not regular:
        raise ValueError(f"{source} is not a file; valid: a TOML file")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        column = error.start - data.rfind(b"\n", 0, error.start)
        raise ValueError(f"{source} is not a TOML table: byte 0x{data[error.start]:02x} at "
                         f"line {line}, column {column} is not UTF-8 text; valid: a UTF-8 "
                         "TOML file") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ValueError(f"{source} is not a valid TOML table: {error}") from None
    except RecursionError:
        raise ValueError(f"{source} is not a TOML table pendular can read: its values are "
                         "nested too deep") from None
