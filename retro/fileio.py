"""Atomic file writes: a reader never sees half a file."""

from __future__ import annotations

import os
import re
import stat
import sys
import tempfile
from collections.abc import Iterable
from pathlib import Path

from retro.errors import InputError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

MAX_INPUT_BYTES = 16 << 20  # the default limit of a read; formats that hold less pass their own


def write_atomic(path: str | os.PathLike, data: bytes | str, inputs: Iterable[str | os.PathLike] = ()) -> Path:
    """Write data to a temp file beside path, then rename it over path: all or nothing."""
    return next(iter(write_all_atomic({path: data}, inputs=inputs)))


def write_all_atomic(outputs: dict, inputs: Iterable[str | os.PathLike] = ()) -> list[Path]:
    """Write every output or none: each to a temp file beside it first, then all renamed into place.

    Refused before anything is written: an output that is one of the `inputs`, one that is not a
    regular file (a device, a FIFO, a folder: `--png /dev/stdout` is not replaced by a file), and the
    same output twice. A symlink to a regular file is written through (the link stays a link). Temp
    files are removed whatever stops the write, Ctrl-C included.
    """
    targets = [_checked_target(Path(path)) for path in outputs]
    if len(set(targets)) != len(targets):
        raise InputError("the same output file is named twice")
    protected = {_resolved(Path(p)) for p in inputs}
    for given, target in zip(outputs, targets):
        if target in protected:
            raise InputError(f"{given}: is an input of this command: refusing to write over it")
    temps: list[str] = []
    try:
        for target, data in zip(targets, outputs.values()):
            payload = data.encode() if isinstance(data, str) else bytes(data)
            directory = target.parent
            try:
                directory.mkdir(parents=True, exist_ok=True)
                fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=directory)
            except OSError as exc:
                raise InputError(f"{target}: cannot write: {exc.strerror or exc}") from None
            temps.append(tmp)
            try:
                with os.fdopen(fd, "wb") as fh:
                    fh.write(payload)
                os.chmod(tmp, _mode_for(target))  # mkstemp makes the file private (0600); a plain write would not
            except OSError as exc:
                raise InputError(f"{target}: cannot write: {exc.strerror or exc}") from None
        for target, tmp in zip(targets, temps):
            try:
                os.replace(tmp, target)
            except OSError as exc:
                raise InputError(f"{target}: cannot write: {exc.strerror or exc}") from None
        temps.clear()
    finally:
        for tmp in temps:
            try:
                os.unlink(tmp)
            except OSError:
                pass
    return targets


def _resolved(path: Path) -> Path:
    try:
        return path.resolve()
    except (OSError, RuntimeError):  # a symlink loop
        return path.absolute()


def _checked_target(path: Path) -> Path:
    target = _resolved(path)
    try:
        exists = target.exists()
    except OSError as exc:  # a name too long, a component that is not a folder, ...
        raise InputError(f"{str(path)[:80]}: cannot write there: {exc.strerror}") from None
    if exists and not target.is_file():
        kind = "a folder" if target.is_dir() else "not a regular file"
        raise InputError(f"{path}: is {kind}: give a file name to write")
    return target


def _mode_for(target: Path) -> int:
    """The permissions open() would give: the existing file's, else 0666 less the umask."""
    try:
        return target.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def _asks(test, path) -> bool:
    try:
        return test(Path(path))
    except (OSError, ValueError):  # a name too long, a NUL byte in it, ...: there is no such file
        return False


def file_option(value, option: str):
    """The file name given to a command-line option; an empty one (a shell variable left unset) is
    an error naming the option, never taken for the option's absence. None stays None."""
    if value is not None and not str(value).strip():
        raise InputError(f"{option}: an empty file name")
    return value


def is_file(path: str | os.PathLike) -> bool:
    """Path.is_file for names users give: False, not an exception, for names no file can have."""
    return _asks(Path.is_file, path)


def is_dir(path: str | os.PathLike) -> bool:
    return _asks(Path.is_dir, path)


def exists(path: str | os.PathLike) -> bool:
    return _asks(Path.exists, path)


def read_bytes(path: str | os.PathLike, what: str = "file", limit: int = MAX_INPUT_BYTES) -> bytes:
    """The bytes of a regular file no larger than `limit` (each format passes the most it can
    hold). A folder, a device, a FIFO or a socket is refused by its kind and a larger file by its
    size, both before anything is read: `/dev/zero` or a 2 GB file costs nothing."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise InputError(f"{str(path)[:200]}: {what} not found") from None
    except (OSError, ValueError) as exc:
        raise InputError(f"{str(path)[:200]}: cannot read {what}: {getattr(exc, 'strerror', None) or exc}") from None
    kind = file_kind(info.st_mode)
    if kind == "a folder":
        raise InputError(f"{path}: {what} is a folder, not a file")
    if kind:
        raise InputError(f"{path}: {what} is {kind}, not a regular file")
    if info.st_size > limit:
        raise InputError(f"{path}: {what} is {info.st_size} bytes; the most read is {size_text(limit)}")
    try:
        with open(path, "rb") as stream:
            data = stream.read(limit + 1)  # the file may have grown since it was measured
    except (OSError, ValueError) as exc:
        raise InputError(f"{str(path)[:200]}: cannot read {what}: {getattr(exc, 'strerror', None) or exc}") from None
    if len(data) > limit:
        raise InputError(f"{path}: {what} is larger than {size_text(limit)}, the most read")
    return data


def file_kind(mode: int) -> str | None:
    """None for a regular file, else what it is, for an error: "a folder", "a device", ..."""
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (a named pipe)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a device"


def size_text(size: int) -> str:
    """1048576 -> "1 MiB", 65538 -> "65538 bytes"."""
    for unit, shift in (("GiB", 30), ("MiB", 20), ("KiB", 10)):
        if size >= 1 << shift and size % (1 << shift) == 0:
            return f"{size >> shift} {unit}"
    return f"{size} bytes"


def read_text(path: str | os.PathLike, what: str = "file", limit: int = MAX_INPUT_BYTES) -> str:
    data = read_bytes(path, what, limit)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: {what} is not UTF-8 text (byte {exc.start})") from None


def parse_toml(data: bytes, shown: str) -> dict:
    """A TOML document, or one line naming the file: not UTF-8, not TOML, nested too deeply (the
    reader recurses per level), or a number longer than Python converts (4,300 digits)."""
    try:
        return tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(f"{shown}: not UTF-8 text (byte {exc.start})") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{shown}: not valid TOML: {exc}") from None
    except RecursionError:
        raise InputError(f"{shown}: not valid TOML: nested too deeply") from None
    except ValueError as exc:  # int() of a huge literal inside the reader
        raise InputError(_huge_integer(data.decode("utf-8"), shown) or f"{shown}: not valid TOML: {exc}") from None


_LONG_INTEGER = re.compile(r"""(?:(?P<key>"[^"\n]*"|'[^'\n]*'|[\w.$-]+)[ \t]*=[ \t]*)?[-+]?\d[\d_]{4299,}""")


def _huge_integer(text: str, shown: str) -> str | None:
    """The error for an integer literal longer than Python converts, with its line and key."""
    match = _LONG_INTEGER.search(text)
    if not match:
        return None
    line = text.count("\n", 0, match.start()) + 1
    key = f" {match.group('key').strip(chr(34) + chr(39))}:" if match.group("key") else ""
    digits = sum(c.isdigit() for c in match.group().split("=")[-1])
    return f"{shown}:{line}:{key} an integer of {digits} digits (Python reads at most 4300)"


def output_folder(path: str | os.PathLike) -> Path:
    """Create an output folder (and parents) up front, so a long run fails before it starts, not after."""
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder}: is a file, not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{folder}: cannot create output folder: {exc.strerror or exc}") from None
    if not os.access(folder, os.W_OK):
        raise InputError(f"{folder}: output folder is not writable")
    return folder
