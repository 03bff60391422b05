"""Writing result files: atomic writes, JSON-safe conversion, figures as PNG/SVG bytes.

Every file a job or a run writes goes through :func:`atomic_write_bytes` (a temporary file
in the same folder, then a rename), so an interrupted run never leaves a half-written file.
Figures are rendered from a :class:`matplotlib.figure.Figure` without pyplot, so writing
files never touches the user's plotting backend.
"""

from __future__ import annotations

import codecs
import errno
import io
import json
import math
import os
import stat
import sys
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..bounds import shorten  # noqa: F401  (used here, and by the readers)
from ._render import SVG_RASTER_POINTS, render_files, render_png, render_svg  # noqa: F401  (SVG_RASTER_POINTS re-exported)

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


def json_text(obj: Any, *, compact: bool = False) -> str:
    """``obj`` as indented JSON text (see :func:`to_plain`), with a final newline; ``compact``:
    no indentation or spaces (json's C encoder: an indented text goes through its Python one,
    2 ms of a halt case's result)."""
    layout: dict[str, Any] = {"separators": (",", ":")} if compact else {"indent": 2}
    return json.dumps(to_plain(obj), allow_nan=False, **layout) + "\n"


#: Byte-order marks of the Unicode encodings a text file may use besides UTF-8 (UTF-32's
#: first: its little-endian mark starts with UTF-16's).
_BOMS = (
    (codecs.BOM_UTF8, "utf-8-sig"),
    (codecs.BOM_UTF32_LE, "utf-32"),
    (codecs.BOM_UTF32_BE, "utf-32"),
    (codecs.BOM_UTF16_LE, "utf-16"),
    (codecs.BOM_UTF16_BE, "utf-16"),
)


def decode_text(data: bytes, label: str, error: type[Exception]) -> str:
    """The text of a file's bytes: UTF-8, or UTF-8/16/32 with a byte-order mark.  Anything
    else (a binary file, Latin-1, UTF-16 without a mark) raises ``error`` with one line
    naming ``label``, the first offending byte and its line."""
    for bom, encoding in _BOMS:
        if data.startswith(bom):
            try:
                return data.decode(encoding)
            except UnicodeDecodeError:
                raise error(f"{label}: not valid {encoding.removesuffix('-sig').upper()} text after its "
                            "byte-order mark; save it as UTF-8") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        if b"\x00" in data[:4096]:
            raise error(f"{label}: a binary file, not text (NUL byte on line {line}); give a UTF-8 text file") from None
        raise error(
            f"{label}: not UTF-8 text (byte 0x{data[exc.start]:02x} on line {line}; Latin-1?); save it as UTF-8"
        ) from None


def check_path_text(path: str | Path, what: str, error: type[Exception]) -> Path:
    """``path`` as a Path, refusing what no file system accepts (an embedded NUL character)."""
    if "\x00" in str(path):
        raise error(f"{what} {shorten(str(path))!r}: a path cannot contain a NUL character")
    return Path(path)


#: Largest input file read [bytes] (a model, scenario or campaign file is a few KB; a URDF with
#: every mesh inlined a few MB).
MAX_INPUT_BYTES = 64 * 1024 * 1024


def path_inside(folder: str | Path, given: str, what: str, error: type[Exception]) -> str:
    """``given`` (a file's ``out``) resolved against ``folder``, which it must lie inside: a
    scenario or campaign file someone sends you cannot write to ``../..`` or an absolute path.
    Paths are compared as written (a symbolic link inside the folder may point elsewhere);
    ``what`` names the field in the error (e.g. ``"run.toml: out"``)."""
    check_path_text(given, what, error)
    base = os.path.normpath(os.path.abspath(folder))
    target = os.path.normpath(os.path.join(base, given))
    if target != base and not target.startswith(base.rstrip(os.sep) + os.sep):
        raise error(
            f"{what} must be a folder inside the file's folder ({shorten(base)!r}); got {shorten(given)!r}: "
            "give --out on the command line to write elsewhere"
        )
    return target


def read_input_bytes(path: str | Path, what: str, error: type[Exception]) -> bytes:
    """The bytes of an input file: a regular file (not a device such as ``/dev/zero`` or a
    named pipe, which could be read forever) of at most :data:`MAX_INPUT_BYTES`; anything else
    raises ``error`` with one line naming ``what`` (e.g. "model file") and the path."""
    path = check_path_text(path, what, error)
    shown = repr(shorten(str(path)))
    try:
        info = path.stat()
        if stat.S_ISDIR(info.st_mode):
            raise error(f"{what} {shown} is a folder, not a file")
        if not stat.S_ISREG(info.st_mode):
            raise error(f"{what} {shown} is not a regular file (a device or a pipe)")
        if info.st_size > MAX_INPUT_BYTES:
            raise error(f"{what} {shown} is {info.st_size / 2**20:.0f} MB; at most {MAX_INPUT_BYTES // 2**20} MB are read")
        return path.read_bytes()
    except FileNotFoundError:
        raise error(f"{what} {shown} does not exist") from None
    except (OSError, RuntimeError) as exc:  # no permission, a loop of links, ...
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc) or type(exc).__name__
        raise error(f"cannot read {what} {shown}: {reason}") from None


def read_text_file(path: str | Path, what: str, error: type[Exception]) -> str:
    """The text of ``path`` (see :func:`read_input_bytes` and :func:`decode_text`)."""
    data = read_input_bytes(path, what, error)
    return decode_text(data, f"{what} {shorten(str(path))!r}", error)


def read_toml_file(path: str | Path, what: str, error: type[Exception]) -> dict[str, Any]:
    """The TOML data of ``path``; a missing, unreadable or invalid file (not UTF-8, not TOML,
    an integer too large for a float) raises ``error`` with one line naming ``what`` (e.g.
    "scenario file") and the path."""
    import tomllib

    text = read_text_file(path, what, error)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{shorten(str(path))}: not valid TOML: {exc}") from None
    check_toml_numbers(data, shorten(str(path)), error)
    return data


def check_toml_numbers(data: Any, label: str, error: type[Exception], where: str = "") -> None:
    """Refuse an integer that no float holds (TOML integers have no size limit; every number
    of jointlock's files ends up a float): ``error`` naming the key."""
    if isinstance(data, dict):
        for key, value in data.items():
            check_toml_numbers(value, label, error, f"{where}.{key}" if where else str(key))
    elif isinstance(data, list):
        for i, value in enumerate(data):
            check_toml_numbers(value, label, error, f"{where} #{i + 1}")
    elif isinstance(data, int) and not isinstance(data, bool) and abs(data) > _FLOAT_MAX_INT:
        raise error(
            f"{label}: {where or 'value'} is an integer of {len(str(abs(data)))} digits, too large for a "
            "number (at most ~1.8e308; the physical bounds of each field are far smaller)"
        )


_FLOAT_MAX_INT = int(sys.float_info.max)


def toml_value(value: Any) -> str:
    """One TOML value: a string, boolean, integer, float, a list of them or an inline table."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)  # a JSON string is a TOML basic string
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(toml_value(x) for x in value) + "]"
    if isinstance(value, Mapping):  # an inline table (a list of them: an array of tables)
        return "{" + ", ".join(f"{_toml_key(k)} = {toml_value(v)}" for k, v in value.items() if v is not None) + "}"
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
    is written directly; a folder is refused (:class:`IsADirectoryError` naming it).  Every
    :class:`OSError` names the path (a full disk says which file it could not write)."""
    try:
        _atomic_write(Path(path), data)
    except OSError as exc:
        if exc.filename is None:
            raise type(exc)(exc.errno, exc.strerror or str(exc), str(path)) from None
        raise


def _atomic_write(given: Path, data: bytes) -> None:
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
    """The figure as PNG bytes (tight bounding box), drawn once (:func:`render_png`)."""
    return render_png(fig, dpi)[0]


def figure_svg(fig: Any, *, tight: bool = True) -> bytes:
    """The figure as SVG (text kept as paths, so it renders the same everywhere); scatters of
    more than :data:`SVG_RASTER_POINTS` points rasterized at the PNG's resolution (for this
    file only: the figure is left as it was).  With ``tight`` the box is measured by an Agg
    draw first; :func:`write_figure` measures it on the PNG's draw instead."""
    bbox = render_png(fig, PNG_DPI)[1] if tight else None
    return render_svg(fig, PNG_DPI, bbox)


def with_svg(names: list[str]) -> list[str]:
    """``names`` with each ``.png`` followed by its ``.svg`` (what :func:`write_figure` writes)."""
    return [m for n in names for m in ((n, n[: -len(".png")] + ".svg") if n.endswith(".png") else (n,))]


def figure_files(fig: Any, *, dpi: int = PNG_DPI, tight: bool = True) -> tuple[bytes, bytes]:
    """The figure as PNG and SVG bytes of the same extent, each drawn once (the SVG's box is
    the one measured on the PNG's draw).  ``tight``: crop to the drawn content (else the
    figure's own size).  The figure is left as it was."""
    if dpi == PNG_DPI:
        return render_files(fig, dpi, tight=tight)
    png, bbox = render_png(fig, dpi, tight=tight)
    return png, render_svg(fig, PNG_DPI, bbox)


def write_figure(fig: Any, folder: str | Path, name: str, *, dpi: int = PNG_DPI, tight: bool = True) -> list[str]:
    """Write the figure as ``folder/name`` (a ``.png`` name) and beside it as SVG (for print
    and reviews: :func:`figure_files`), atomically; returns both names.  ``tight``: crop to the
    drawn content (else the figure's own size, as :func:`write_png`).  The figure is left open."""
    if not name.endswith(".png"):
        raise ValueError(f"write_figure writes a .png name (and its .svg); got {name!r}")
    folder = Path(folder)
    png, svg = figure_files(fig, dpi=dpi, tight=tight)
    atomic_write_bytes(folder / name, png)
    atomic_write_bytes(folder / (name[: -len(".png")] + ".svg"), svg)
    return [name, name[: -len(".png")] + ".svg"]


def save_figure(fig: Any, folder: str | Path, stem: str, *, dpi: int = PNG_DPI, svg: bool = True) -> bytes:
    """Write ``folder/stem.png`` (and ``folder/stem.svg`` unless ``svg=False``) atomically;
    returns the PNG bytes (to embed in a report).  The figure is left open."""
    if not svg:
        png = render_png(fig, dpi)[0]
    else:
        png, svg_bytes = figure_files(fig, dpi=dpi)
        atomic_write_bytes(Path(folder) / f"{stem}.svg", svg_bytes)
    atomic_write_bytes(Path(folder) / f"{stem}.png", png)
    return png


def write_png(fig: Any, path: str | Path, *, dpi: int = PNG_DPI) -> None:
    """``fig.savefig(path, dpi=dpi)`` as PNG (the figure's own bounding box), written
    atomically.  The figure is left open."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    atomic_write_bytes(path, buf.getvalue())
