"""Reading every file the project reads, and writing results, without surprises.

One place checks what a hostile or careless input could do before any parser sees it:
only regular files (no FIFO, device or folder), a size limit, UTF-8 text, a nesting
depth limit checked on the event stream (so no recursive composer can overflow the
stack), duplicate keys refused, numbers too long to convert refused, image sizes read
from the header before decoding. Every problem is an ``InputFileError`` naming the file
and, where there is one, the field. Writing goes through a temporary file and
``os.replace`` so a crash or a full disk never truncates an existing result.
"""

from __future__ import annotations

import json
import os
import re
import stat
import struct
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

from pmnav_bt.errors import PmNavError

# Size limits per kind of file (bytes). Generous for real files, far below memory trouble.
MAX_BYTES = {
    "building": 8 << 20,
    "config": 1 << 20,
    "episodes": 64 << 20,
    "ros_map": 1 << 20,
    "tree log": 256 << 20,
    "image": 256 << 20,
    "weights": 4 << 30,
}
MAX_DEPTH = 32  # nesting of mappings/sequences; project files need fewer than 8
MAX_ALIASES = 1000  # YAML alias uses in one file
MAX_IMAGE_SIDE = 20_000  # pixels
MAX_IMAGE_PIXELS = 64_000_000  # width x height (a 8000 x 8000 plan at 0.05 m is 400 m)
MAX_PATH_CHARS = 4096
MAX_NAME_CHARS = 100  # a file name made from user text


class InputFileError(PmNavError):
    """A file the user named cannot be read as what it should be."""

    def __init__(self, path: str | Path, message: str, field: str = ""):
        self.path = str(path)
        self.field = field
        self.message = message
        where = f"{self.path}: {field}" if field else self.path
        super().__init__(f"{where}: {message}")


class OutputError(PmNavError):
    """An output path that cannot be written (checked before any work starts)."""


# -- reading ---------------------------------------------------------------------------


def _stat_regular(path: Path, kind: str) -> os.stat_result:
    """The stat of ``path`` if it is a readable regular file within the size limit."""
    text = str(path)
    if len(text) > MAX_PATH_CHARS or any(len(p) > 255 for p in path.parts):
        raise InputFileError(_short(text), "path too long (a name over 255 characters)")
    if "\0" in text:
        raise InputFileError(repr(text), "path contains a NUL character")
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise InputFileError(path, f"cannot read {kind} file: no such file") from None
    except OSError as err:
        raise InputFileError(path, f"cannot read {kind} file: {err.strerror}") from None
    if stat.S_ISDIR(st.st_mode):
        raise InputFileError(path, f"is a folder, not a {kind} file")
    if not stat.S_ISREG(st.st_mode):
        raise InputFileError(path, f"not a regular file (a pipe or device?); give a {kind} file")
    limit = MAX_BYTES.get(kind, 8 << 20)
    if st.st_size > limit:
        raise InputFileError(path, f"{kind} file is {_mib(st.st_size)}; the limit is {_mib(limit)}")
    return st


def read_bytes(path: str | Path, kind: str) -> bytes:
    """The bytes of a regular file of at most the size limit of ``kind``."""
    path = Path(path)
    _stat_regular(path, kind)
    limit = MAX_BYTES.get(kind, 8 << 20)
    try:
        # O_NONBLOCK: should the file be swapped for a FIFO after the stat, open does not hang.
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as f:
            if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                raise InputFileError(path, f"not a regular file; give a {kind} file")
            data = f.read(limit + 1)
    except OSError as err:
        raise InputFileError(path, f"cannot read {kind} file: {err.strerror}") from None
    if len(data) > limit:
        raise InputFileError(path, f"{kind} file is over the limit of {_mib(limit)}")
    return data


def decode_utf8(data: bytes, path: str | Path, kind: str) -> str:
    """UTF-8 text (a BOM is allowed), or an error saying where the first bad byte is."""
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        hint = " (UTF-16?)" if data[:2] in (b"\xff\xfe", b"\xfe\xff") else ""
        raise InputFileError(
            path, f"not UTF-8 text{hint}: bad byte at offset {err.start}; save the {kind} as UTF-8"
        ) from None
    if "\0" in text:
        raise InputFileError(path, f"contains NUL characters; a {kind} file is text")
    return text


def read_text(path: str | Path, kind: str) -> str:
    """A regular, size-limited UTF-8 text file."""
    return decode_utf8(read_bytes(path, kind), path, kind)


def is_regular_file(path: str | Path) -> bool:
    """True for an existing regular file; False (never an exception) for anything else."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


# -- YAML ------------------------------------------------------------------------------

_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _StrictLoader(_Loader):  # type: ignore[misc,valid-type]
    """Safe loading that refuses duplicate keys."""


def _construct_mapping(loader, node, deep=False):
    seen: dict[Any, int] = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=True)
        try:
            hash(key)
        except TypeError:
            raise yaml.constructor.ConstructorError(
                None, None, "a mapping key must be a plain value", key_node.start_mark
            ) from None
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None,
                None,
                f"duplicate key {key!r} (first at line {seen[key] + 1})",
                key_node.start_mark,
            )
        seen[key] = key_node.start_mark.line
    return yaml.SafeLoader.construct_mapping(loader, node, deep)


_StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def _yaml_where(err: yaml.YAMLError) -> str:
    mark = getattr(err, "problem_mark", None) or getattr(err, "context_mark", None)
    return f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""


def check_yaml_shape(text: str, path: str | Path) -> None:
    """Walk the YAML event stream (no recursion) and refuse deep nesting or alias floods."""
    depth = aliases = 0
    try:
        for ev in yaml.parse(text, Loader=_Loader):
            if isinstance(ev, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
                depth += 1
                if depth > MAX_DEPTH:
                    raise InputFileError(
                        path, f"nested deeper than {MAX_DEPTH} levels", _mark(ev.start_mark)
                    )
            elif isinstance(ev, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
                depth -= 1
            elif isinstance(ev, yaml.AliasEvent):
                aliases += 1
                if aliases > MAX_ALIASES:
                    raise InputFileError(
                        path, f"more than {MAX_ALIASES} aliases (*name)", _mark(ev.start_mark)
                    )
    except yaml.YAMLError as err:
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        if "nesting depth" in problem:  # PyYAML 6.0.3+ stops deeper nesting in its scanner
            raise InputFileError(
                path, f"nested deeper than {MAX_DEPTH} levels", _yaml_where(err)
            ) from None
        raise InputFileError(path, f"not valid YAML: {problem}", _yaml_where(err)) from None


def _mark(mark) -> str:
    return f"line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""


def parse_yaml(text: str, path: str | Path) -> Any:
    """YAML text to plain data: safe tags only, no duplicate keys, bounded depth."""
    check_yaml_shape(text, path)
    try:
        return yaml.load(text, Loader=_StrictLoader)  # noqa: S506 - a safe loader
    except yaml.YAMLError as err:
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise InputFileError(path, f"not valid YAML: {problem}", _yaml_where(err)) from None
    except (ValueError, OverflowError, RecursionError) as err:  # int over 4300 digits, ...
        raise InputFileError(path, f"not valid YAML: {_first_line(err)}") from None


def load_yaml(path: str | Path, kind: str) -> Any:
    """Read a YAML file of ``kind`` (building, config, ros_map) into plain data."""
    return parse_yaml(read_text(path, kind), path)


def parse_yaml_value(raw: str, what: str) -> Any:
    """One YAML value from the command line (``--set key=VALUE``); errors name ``what``."""
    if len(raw) > 10_000:
        raise PmNavError(f"{what}: value too long ({len(raw)} characters)")
    try:
        return parse_yaml(raw, what)
    except InputFileError as err:
        raise PmNavError(
            f"{what}: {err.message}" + (f" ({err.field})" if err.field else "")
        ) from None


def weights_file(path: str | Path) -> Path:
    """A model weights file (for safetensors or ``torch.load(weights_only=True)``), checked
    to be a regular file within the size limit before any loader opens it."""
    path = Path(path)
    _stat_regular(path, "weights")
    return path


# -- JSON ------------------------------------------------------------------------------


def check_json_depth(text: str, path: str | Path, limit: int = MAX_DEPTH, where: str = "") -> None:
    """Refuse JSON nested deeper than ``limit`` (counted on brackets outside strings)."""
    # Strip strings first (escapes included), then count brackets.
    stripped = _JSON_STRING.sub('""', text)
    depth = 0
    for m in _BRACKETS.finditer(stripped):
        if m.group() in "[{":
            depth += 1
            if depth > limit:
                raise InputFileError(path, f"nested deeper than {limit} levels", where)
        else:
            depth -= 1


_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.S)
_BRACKETS = re.compile(r"[\[\]{}]")


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict:
    out: dict = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"duplicate key {k!r}")
        out[k] = v
    return out


def _no_constants(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def parse_json(text: str, path: str | Path, where: str = "", allow_nan: bool = False) -> Any:
    """JSON text to plain data: bounded depth, no duplicate keys, no NaN/Infinity."""
    check_json_depth(text, path, where=where)
    extra = {} if allow_nan else {"parse_constant": _no_constants}
    try:
        return json.loads(text, object_pairs_hook=_no_duplicates, **extra)
    except json.JSONDecodeError as err:
        loc = where or f"line {err.lineno}, column {err.colno}"
        raise InputFileError(path, f"not valid JSON: {err.msg}", loc) from None
    except (ValueError, RecursionError) as err:
        raise InputFileError(path, f"not valid JSON: {_first_line(err)}", where) from None


def load_json(path: str | Path, kind: str) -> Any:
    """Read a JSON file of ``kind`` (episodes) into plain data."""
    return parse_json(read_text(path, kind), path)


def iter_text_lines(path: str | Path, kind: str) -> Iterator[tuple[int, str, bool]]:
    """(line number, text, ends with a newline) for each line of a UTF-8 file."""
    path = Path(path)
    _stat_regular(path, kind)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as f:
            for i, raw in enumerate(f, 1):
                if len(raw) > 64 << 20:
                    raise InputFileError(path, "line longer than 64 MiB", f"line {i}")
                try:
                    text = raw.decode("utf-8")
                except UnicodeDecodeError:
                    raise InputFileError(
                        path, f"not a {kind} (not UTF-8 text)", f"line {i}"
                    ) from None
                yield i, text.rstrip("\r\n"), raw.endswith(b"\n")
    except OSError as err:
        raise InputFileError(path, f"cannot read {kind}: {err.strerror}") from None


# -- images ----------------------------------------------------------------------------


def image_size(path: str | Path, field: str = "image") -> tuple[int, int]:
    """(width, height) read from a PNG, PGM/PPM or JPEG header, checked against the limits."""
    path = Path(path)
    _stat_regular(path, "image")
    try:
        with open(path, "rb") as f:
            head = f.read(64 << 10)
    except OSError as err:
        raise InputFileError(path, f"cannot read image: {err.strerror}", field) from None
    if head.startswith(b"\x89PNG\r\n\x1a\n") and len(head) >= 24 and head[12:16] == b"IHDR":
        w, h = struct.unpack(">II", head[16:24])
    elif head[:2] in (b"P2", b"P5", b"P3", b"P6"):
        w, h = _pnm_size(head, path, field)
    elif head[:2] == b"\xff\xd8":
        w, h = _jpeg_size(head, path, field)
    else:
        raise InputFileError(path, "not a PNG, PGM or JPEG image", field)
    if w < 1 or h < 1:
        raise InputFileError(path, f"image is {w}x{h} pixels", field)
    if max(w, h) > MAX_IMAGE_SIDE or w * h > MAX_IMAGE_PIXELS:
        raise InputFileError(
            path,
            f"image is {w}x{h} pixels; the limit is {MAX_IMAGE_SIDE} a side and "
            f"{MAX_IMAGE_PIXELS // 1_000_000} megapixels (scale it down)",
            field,
        )
    return w, h


def _pnm_size(head: bytes, path: Path, field: str) -> tuple[int, int]:
    tokens: list[bytes] = []
    body = re.sub(rb"#[^\n]*", b" ", head[2:4096])
    for tok in body.split():
        tokens.append(tok)
        if len(tokens) == 2:
            break
    try:
        w, h = int(tokens[0][:12]), int(tokens[1][:12])
    except (IndexError, ValueError):
        raise InputFileError(path, "bad PGM header (width and height)", field) from None
    return w, h


def _jpeg_size(head: bytes, path: Path, field: str) -> tuple[int, int]:
    i = 2
    while i + 9 < len(head):
        if head[i] != 0xFF:
            break
        marker = head[i + 1]
        if marker in (0xD8, 0x01) or 0xD0 <= marker <= 0xD7:
            i += 2
            continue
        (seglen,) = struct.unpack(">H", head[i + 2 : i + 4])
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):
            h, w = struct.unpack(">HH", head[i + 5 : i + 9])
            return w, h
        i += 2 + seglen
    raise InputFileError(path, "bad JPEG header (no frame size in the first 64 KiB)", field)


# -- writing ---------------------------------------------------------------------------


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` via a temporary file in the same folder and ``os.replace``."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically: the old file stays whole until the new one is."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name[:40]}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def check_output_dir(path: str | Path, option: str = "--out") -> Path:
    """A folder that exists or can be made and written to; raise OutputError otherwise."""
    path = Path(path)
    _check_path_text(path, option)
    try:
        if path.exists() and not path.is_dir():
            raise OutputError(f"{option} {_short(str(path))}: is a file, not a folder")
        for parent in path.parents:
            if parent.exists() and not parent.is_dir():
                raise OutputError(f"{option} {_short(str(path))}: {parent} is a file, not a folder")
        path.mkdir(parents=True, exist_ok=True)
        probe = tempfile.NamedTemporaryFile(dir=path, prefix=".pmnav-write-test.")  # noqa: SIM115
        probe.close()
    except OSError as err:
        raise OutputError(
            f"{option} {_short(str(path))}: cannot write there ({err.strerror})"
        ) from None
    return path


def check_output_file(
    path: str | Path, option: str = "--out", suffixes: tuple[str, ...] = ()
) -> Path:
    """A file path whose folder is writable and whose suffix is one of ``suffixes``."""
    path = Path(path)
    _check_path_text(path, option)
    if suffixes and path.suffix.lower() not in suffixes:
        raise OutputError(
            f"{option} {_short(str(path))}: give a file name ending in {' or '.join(suffixes)}"
        )
    if path.is_dir():
        raise OutputError(f"{option} {_short(str(path))}: is a folder; give a file name")
    check_output_dir(path.parent if str(path.parent) else Path("."), option)
    return path


def _check_path_text(path: Path, option: str) -> None:
    text = str(path)
    if "\0" in text:
        raise OutputError(f"{option}: the path contains a NUL character")
    if len(text) > MAX_PATH_CHARS or any(len(p) > 255 for p in path.parts):
        raise OutputError(f"{option} {_short(text)}: path too long (a name over 255 characters)")


_UNSAFE = re.compile(r"[^A-Za-z0-9._+-]+")


def safe_filename(text: str, max_chars: int = MAX_NAME_CHARS) -> str:
    """A file name made from user text: no separators, no leading dots, at most ``max_chars``."""
    name = _UNSAFE.sub("_", text).strip("._-")
    return name[:max_chars] or "unnamed"


# -- helpers ---------------------------------------------------------------------------


def _mib(n: int) -> str:
    return f"{n / (1 << 20):.1f} MiB" if n >= 1 << 20 else f"{n} bytes"


def _short(text: str, n: int = 60) -> str:
    return text if len(text) <= n else text[: n - 3] + "..."


def _first_line(err: BaseException) -> str:
    s = str(err).strip()
    if "integer string conversion" in s:
        return "a number with more than 4300 digits"
    return s.splitlines()[0] if s else type(err).__name__
