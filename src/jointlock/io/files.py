"""Writing result files: atomic writes, JSON-safe conversion, figures as PNG/SVG bytes.

Every file a job or a run writes goes through :func:`atomic_write_bytes` (a temporary file
in the same folder, then a rename), so an interrupted run never leaves a half-written file.
Figures are rendered from a :class:`matplotlib.figure.Figure` without pyplot, so writing
files never touches the user's plotting backend.
"""

from __future__ import annotations

import errno
import io
import json
import math
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

#: Resolution of every PNG written [dots per inch].
PNG_DPI = 110


def to_plain(obj: Any) -> Any:
    """``obj`` as plain JSON data: arrays -> lists, numpy scalars -> Python numbers, tuples ->
    lists, dictionary keys -> strings, non-finite floats -> ``None`` (JSON has no NaN)."""
    if isinstance(obj, np.ndarray):
        return to_plain(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, dict):
        return {str(k): to_plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_plain(v) for v in obj]
    return obj


def json_text(obj: Any) -> str:
    """``obj`` as indented JSON text (see :func:`to_plain`), with a final newline."""
    return json.dumps(to_plain(obj), indent=2, allow_nan=False) + "\n"


def read_toml_file(path: str | Path, what: str, error: type[Exception]) -> dict[str, Any]:
    """The TOML data of ``path``; a missing, unreadable or invalid file raises ``error`` with
    one line naming ``what`` (e.g. "scenario file") and the path."""
    import tomllib

    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise error(f"{what} {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"cannot read {what} {str(path)!r}: {exc}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML: {exc}") from None


def toml_value(value: Any) -> str:
    """One TOML value: a string, boolean, integer, float or a list of them."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)  # a JSON string is a TOML basic string
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(toml_value(x) for x in value) + "]"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    return repr(float(value))


def toml_document(data: Mapping[str, Any]) -> str:
    """``data`` as TOML text: its plain values first, then each table (``[name]``, nested
    tables as ``[name.sub]``); ``None`` values are left out (TOML has no null)."""

    def write(table: Mapping[str, Any], prefix: str) -> list[str]:
        lines = [f"{_toml_key(k)} = {toml_value(v)}" for k, v in table.items() if v is not None and not isinstance(v, Mapping)]
        for key, sub in table.items():
            if isinstance(sub, Mapping):
                name = f"{prefix}{_toml_key(key)}"
                lines += ["", f"[{name}]", *write(sub, name + ".")]
        return lines

    return "\n".join(write(data, "")).lstrip("\n") + "\n"


def _toml_key(key: str) -> str:
    return key if key.replace("_", "").replace("-", "").isalnum() and key.isascii() else json.dumps(key)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` via a temporary file and a rename, so an interrupted run
    never leaves a half-written file (parent folders are created).

    A symbolic link is written through (the file it points to is replaced, the link kept); a
    path under ``/dev`` or ``/proc`` (``/dev/stdout``) or that is not a regular file (a pipe)
    is written directly; a folder is refused (:class:`IsADirectoryError` naming it)."""
    given = Path(path)
    if str(given).startswith(("/dev/", "/proc/")):  # a device, a pipe, a redirected stdout
        with open(given, "ab") as fh:  # appending: a redirected stdout keeps what came before
            fh.write(data)
        return
    path = Path(os.path.realpath(given))
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a folder, not a file", str(given))
    if path.exists() and not path.is_file():  # a named pipe: no rename over it
        with open(path, "wb") as fh:
            fh.write(data)
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    """:func:`atomic_write_bytes` of ``text`` encoded as UTF-8."""
    atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path: str | Path, obj: Any) -> None:
    """:func:`atomic_write_text` of :func:`json_text` (non-finite floats written as null)."""
    atomic_write_text(path, json_text(obj))


def csv_text(columns: dict[str, np.ndarray], fmt: str = "{:.9g}") -> str:
    """A CSV table, one column per ``{header: (rows,) values}``, header line first."""
    header = ",".join(columns)
    rows = np.column_stack([np.asarray(v, dtype=float) for v in columns.values()])
    body = "\n".join(",".join(fmt.format(v) for v in row) for row in rows)
    return header + "\n" + body + "\n"


def npz_bytes(*, compressed: bool = False, **arrays: Any) -> bytes:
    """``np.savez`` (``np.savez_compressed`` with ``compressed=True``) of ``arrays`` into
    bytes (to write atomically)."""
    buf = io.BytesIO()
    (np.savez_compressed if compressed else np.savez)(buf, **arrays)
    return buf.getvalue()


def figure_png(fig: Any, dpi: int = PNG_DPI) -> bytes:
    """The figure as PNG bytes (tight bounding box)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    return buf.getvalue()


def figure_svg(fig: Any) -> bytes:
    """The figure as SVG (text kept as paths, so it renders the same everywhere)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="svg", bbox_inches="tight")
    return buf.getvalue()


def save_figure(fig: Any, folder: str | Path, stem: str, *, dpi: int = PNG_DPI, svg: bool = True) -> bytes:
    """Write ``folder/stem.png`` (and ``folder/stem.svg`` unless ``svg=False``) atomically;
    returns the PNG bytes (to embed in a report).  The figure is left open."""
    png = figure_png(fig, dpi=dpi)
    atomic_write_bytes(Path(folder) / f"{stem}.png", png)
    if svg:
        atomic_write_bytes(Path(folder) / f"{stem}.svg", figure_svg(fig))
    return png


def write_png(fig: Any, path: str | Path, *, dpi: int = PNG_DPI) -> None:
    """``fig.savefig(path, dpi=dpi)`` as PNG (the figure's own bounding box), written
    atomically.  The figure is left open."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    atomic_write_bytes(path, buf.getvalue())
