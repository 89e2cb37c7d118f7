"""Files in and out of a command: reads with one-line errors and a size limit, recorded as the
command's inputs; writes staged and committed all at once, never over an input, never through a
link (docs/files.md)."""

from __future__ import annotations

import functools
import os
import re
import stat
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from retro import interrupts
from retro.errors import InputError

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX: commits are not serialised between processes
    fcntl = None

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

MAX_INPUT_BYTES = 16 << 20  # the default limit of a read; formats that hold less pass their own
TEMP_SUFFIX = ".retro-tmp"  # every temp file retro makes beside an output ends so
LOCK_SECONDS = 60  # how long a commit waits for another command committing into the same folder


class _Output:
    """An output staged in a session: its temp file beside the target, until the commit."""

    def __init__(self, target: Path, given: str, what: str, temp: Path) -> None:
        self.target, self.given, self.what, self.temp = target, given, what, temp


class _Session:
    """The files of one command: every input it read (by device and inode, so that a link, `./`,
    `../` or a hard link names the same file) and every output it staged."""

    def __init__(self) -> None:
        self.inputs: dict[tuple[int, int], str] = {}
        self.outputs: dict[Path, _Output] = {}
        self.created: list[Path] = []  # folders made for outputs, removed again if nothing is written

    def commit(self) -> None:
        """Every staged output renamed into place, or (on any failure) none: signals wait meanwhile,
        and a rename that fails puts back the files already replaced."""
        outputs = list(self.outputs.values())
        if not outputs:
            return
        interrupts.raise_if_stopping()  # never commit a command that was told to stop
        with _folders_locked({o.target.parent for o in outputs}), interrupts.deferred():
            for output in outputs:  # a file may have become an input or a link since it was staged
                _check_target(output.target, output.given, output.what, self)
            replaced: list[tuple[_Output, Path | None]] = []
            try:
                for output in outputs:
                    previous = _keep_previous(output.target)
                    try:
                        os.replace(output.temp, output.target)
                    except OSError:
                        if previous is not None:
                            _remove(previous)
                        raise
                    replaced.append((output, previous))
            except OSError as exc:
                _put_back(replaced)
                raise InputError(f"{output.given}: cannot write: {exc.strerror or exc}") from None
            for _, previous in replaced:
                if previous is not None:
                    _remove(previous)
            self.outputs.clear()
            self.created.clear()

    def abort(self) -> None:
        with interrupts.deferred():
            for output in self.outputs.values():
                _remove(output.temp)
            self.outputs.clear()
            for folder in reversed(self.created):
                try:
                    folder.rmdir()  # only if empty: a file someone else put there stays
                except OSError:
                    pass
            self.created.clear()


_session: _Session | None = None
_recorders: list[set] = []  # reads collected for `cached_reads` and `recording_reads`: (key, shown, stamp)


@contextmanager
def command_files() -> Iterator[_Session]:
    """The files of one command, all or nothing: inside, every file read through this module is an
    input no output may replace, and every write is staged beside its target; at the end all the
    outputs are renamed into place together, or, if anything stops the command (an error, Ctrl-C,
    SIGTERM), the staged files are removed and no output is touched. A nested use joins the outer
    command (the demo's steps write as one command)."""
    global _session
    if _session is not None:
        yield _session
        return
    session = _session = _Session()
    try:
        yield session
        session.commit()
    except BaseException:
        session.abort()
        raise
    finally:
        _session = None


def all_or_nothing(function: Callable) -> Callable:
    """A command function whose files are one `command_files()` session."""
    @functools.wraps(function)
    def command(*args, **kwargs):
        with command_files():
            return function(*args, **kwargs)
    return command


def note_input(path: str | os.PathLike, what: str = "file") -> None:
    """Record a file read other than through `read_bytes` (by the assembler, by Python's import) as
    an input of the current command. A name that is no file is ignored."""
    try:
        status = os.stat(path)
    except (OSError, ValueError):
        return
    _record((status.st_dev, status.st_ino), f"{what} {path}", _stamp(path, status))


def _stamp(path: str | os.PathLike, status: os.stat_result) -> tuple:
    """A file as it was read: its path, size, modification time and inode (an edit or a replacement
    changes one of them)."""
    return os.path.abspath(path), status.st_size, status.st_mtime_ns, status.st_ino


def _record(key: tuple[int, int], shown: str, stamp: tuple | None = None) -> None:
    if _session is not None:
        _session.inputs.setdefault(key, shown)
    for recorder in _recorders:
        recorder.add((key, shown, stamp))


@contextmanager
def recording_reads() -> Iterator[set]:
    """The files read through this module inside the block (a cached answer's files too), for
    `reads_unchanged` to tell later whether anything built from them is stale."""
    reads: set = set()
    _recorders.append(reads)
    try:
        yield reads
    finally:
        _recorders.remove(reads)


def reads_unchanged(reads: Iterable[tuple]) -> bool:
    """Whether every file in `reads` (recording_reads) still has the path, size, modification time
    and inode it was read with."""
    for _, _, stamp in reads:
        if stamp is None:
            continue
        try:
            status = os.stat(stamp[0])
        except OSError:
            return False
        if (status.st_size, status.st_mtime_ns, status.st_ino) != stamp[1:]:
            return False
    return True


def cached_reads(maxsize: int | None = 128) -> Callable:
    """functools.lru_cache for a function that reads files: an answer is kept while every file the
    call read is unchanged (path, size, modification time, inode), and a cached answer records those
    files as inputs of the current command again, so a cache never hides an input."""
    def decorate(function: Callable) -> Callable:
        stale: dict[tuple, int] = {}  # args whose answer was read again: how often

        @functools.lru_cache(maxsize=maxsize)
        def remembered(generation: int, *args):
            with recording_reads() as reads:
                result = function(*args)
            return result, tuple(reads)

        @functools.wraps(function)
        def cached(*args):
            result, reads = remembered(stale.get(args, 0), *args)
            if not reads_unchanged(reads):
                stale[args] = stale.get(args, 0) + 1
                result, reads = remembered(stale[args], *args)
            for read in reads:
                _record(*read)
            return result

        cached.cache_clear = remembered.cache_clear
        cached.cache_info = remembered.cache_info
        return cached
    return decorate


def write_atomic(path: str | os.PathLike, data: bytes | str, inputs: Iterable[str | os.PathLike] = (),
                 what: str = "output") -> Path:
    """Write data to `path` as part of the current command (see `command_files`), or alone: a temp
    file beside the target, renamed over it at the end. Returns the target (its folder resolved)."""
    with command_files() as session:
        for extra in inputs:
            note_input(extra, "input")
        return _stage(session, path, data, what)


def write_all_atomic(outputs: dict, inputs: Iterable[str | os.PathLike] = (), what: dict | None = None) -> list[Path]:
    """Write every output or none (see `command_files`); `what` names each output in errors
    (`{path: "--labels"}`)."""
    what = what or {}
    with command_files() as session:
        for extra in inputs:
            note_input(extra, "input")
        return [_stage(session, path, data, what.get(path, "output")) for path, data in outputs.items()]


def _stage(session: _Session, path: str | os.PathLike, data: bytes | str, what: str) -> Path:
    interrupts.raise_if_stopping()
    given = str(path)
    target = _target(Path(path))
    _check_target(target, given, what, session)
    if target in session.outputs:
        first = session.outputs[target]
        raise InputError(f"{given}: the {what} and the {first.what} ({first.given}) are the same file")
    payload = data.encode() if isinstance(data, str) else bytes(data)
    with interrupts.deferred():  # the folder and the temp file are recorded the moment they exist
        try:
            _make_folder(target.parent, session)
            fd, temp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=TEMP_SUFFIX, dir=target.parent)
        except OSError as exc:
            raise InputError(f"{given}: cannot write: {exc.strerror or exc}") from None
        session.outputs[target] = _Output(target, given, what, Path(temp))
    try:
        with os.fdopen(fd, "wb") as fh:
            _write_hook(target)
            fh.write(payload)
        os.chmod(temp, _mode_for(target))  # mkstemp makes the file private (0600); a plain write would not
    except OSError as exc:
        raise InputError(f"{given}: cannot write: {exc.strerror or exc}") from None
    return target


def _write_hook(target: Path) -> None:
    """Called inside the write window (a temp file exists, nothing is in place): the fault tests
    replace it to send a signal or fill the disk at exactly this moment."""


def _target(path: Path) -> Path:
    """Where an output goes: its folder resolved (links, `.`, `..`), its own name kept, so that a
    link in the last place is seen (and refused), not followed."""
    if path.name in ("", ".", ".."):
        return _resolved(path)
    return _resolved(path.parent) / path.name


def _check_target(target: Path, given: str, what: str, session: _Session) -> None:
    """Refuse an output that is a link, not a regular file, or one of the command's inputs."""
    try:
        status = os.lstat(target)
    except FileNotFoundError:
        return
    except (OSError, ValueError) as exc:  # a name too long, a component that is not a folder, ...
        raise InputError(f"{given[:80]}: cannot write there: {getattr(exc, 'strerror', None) or exc}") from None
    if stat.S_ISLNK(status.st_mode):
        raise InputError(f"{given}: is a symbolic link: refusing to write through it (name the file itself)")
    if not stat.S_ISREG(status.st_mode):
        kind = "a folder" if stat.S_ISDIR(status.st_mode) else "not a regular file"
        raise InputError(f"{given}: is {kind}: give a file name to write")
    source = session.inputs.get((status.st_dev, status.st_ino))
    if source is not None:
        raise InputError(f"{given}: is an input of this command ({source}): refusing to write over it")


def _make_folder(folder: Path, session: _Session) -> None:
    missing = []
    while not folder.exists():
        missing.append(folder)
        folder = folder.parent
    for made in reversed(missing):
        try:
            made.mkdir()
        except FileExistsError:  # another command made it meanwhile: it is not ours to remove
            continue
        session.created.append(made)


def _keep_previous(target: Path) -> Path | None:
    """A hard link to the file about to be replaced, so a failed commit can put it back."""
    if not target.exists():
        return None
    keep = target.with_name(f".{target.name}.{os.getpid()}.previous{TEMP_SUFFIX}")
    try:
        _remove(keep)
        os.link(target, keep)
    except OSError:  # a file system without hard links: this one cannot be put back
        return None
    return keep


def _put_back(replaced: list[tuple[_Output, Path | None]]) -> None:
    for output, previous in reversed(replaced):
        try:
            if previous is not None:
                os.replace(previous, output.target)
            else:  # there was no file before
                _remove(output.target)
        except OSError:
            pass


def _remove(path: Path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


@contextmanager
def _folders_locked(folders: set[Path]) -> Iterator[None]:
    """Two commands committing into one folder at once take turns (flock on the folder), so each
    leaves a whole set: the later one's, never a mix."""
    if fcntl is None:
        yield
        return
    held = []
    try:
        for folder in sorted(folders):
            try:
                fd = os.open(folder, os.O_RDONLY)
            except OSError:
                continue
            held.append(fd)
            deadline = time.monotonic() + LOCK_SECONDS
            while True:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    if time.monotonic() > deadline:
                        raise InputError(f"{folder}: another command is writing there (waited {LOCK_SECONDS} s)") from None
                    time.sleep(0.01)
                except OSError:  # a file system without locks
                    break
        yield
    finally:
        for fd in held:
            os.close(fd)


def _resolved(path: Path) -> Path:
    try:
        return path.resolve()
    except (OSError, RuntimeError):  # a symlink loop
        return path.absolute()


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
        return test(_staged_or(path))
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
    hold), recorded as an input of the current command. A folder, a device, a FIFO or a socket is
    refused by its kind and a larger file by its size, both before anything is read: `/dev/zero` or
    a 2 GB file costs nothing."""
    source = _staged_or(path)
    try:
        info = os.stat(source)
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
        with open(source, "rb") as stream:
            status = os.fstat(stream.fileno())
            _record((status.st_dev, status.st_ino), f"{what} {path}", _stamp(source, status))
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


def toml_text(doc: dict, tables: int | None = None) -> str:
    """`doc` as TOML text that `parse_toml` reads back equal: strings, integers, floats, booleans,
    dates and times, arrays and tables. A table nested at most `tables` deep is a [section] (an
    array of them [[sections]]), a deeper one inline ({ k = v }) as specs write their inputs; None:
    every table a section."""
    sections: list[str] = []
    _toml_section(doc, (), tables, sections)
    return "\n\n".join(sections) + "\n" if sections else ""


def toml_value(value) -> str:
    """One value as inline TOML (a table as { k = v }, an array as [a, b])."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)  # inf, -inf, nan and 1e+16 are TOML floats too
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {toml_value(v)}" for k, v in value.items()) + " }" if value else "{}"
    if hasattr(value, "isoformat"):  # datetime, date, time as tomllib gives them
        return value.isoformat()
    raise TypeError(f"no TOML for {type(value).__name__}")


_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
_TOML_ESCAPES = {"\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r", '"': '\\"', "\\": "\\\\"}
_TOML_UNSAFE = re.compile(r'[\x00-\x1f\x7f"\\]')  # what a basic string may not hold as it is


def _toml_string(text: str) -> str:
    return '"' + _TOML_UNSAFE.sub(lambda m: _TOML_ESCAPES.get(m[0], f"\\u{ord(m[0]):04x}"), text) + '"'


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.fullmatch(key) else _toml_string(key)


def _toml_section(table: dict, path: tuple[str, ...], tables: int | None, out: list[str],
                  header: str | None = None) -> None:
    """`table`'s own keys under `header`, then each of its sections (arrays of tables element by element)."""
    as_section = tables is None or len(path) < tables
    nested = {key: value for key, value in table.items() if as_section and (
        isinstance(value, dict) or isinstance(value, list) and value and all(isinstance(v, dict) for v in value))}
    lines = [] if header is None else [header]
    lines += [f"{_toml_key(key)} = {toml_value(value)}" for key, value in table.items() if key not in nested]
    if lines:
        out.append("\n".join(lines))
    for key, value in nested.items():
        name = ".".join(_toml_key(step) for step in (*path, key))
        if isinstance(value, dict):
            _toml_section(value, (*path, key), tables, out, f"[{name}]")
        else:
            for item in value:
                _toml_section(item, (*path, key), tables, out, f"[[{name}]]")


def _staged_or(path: str | os.PathLike) -> Path:
    """The temp file of an output the current command has staged but not yet put in place (the demo
    runs the PRG it has just assembled), else the path itself."""
    if _session is not None and _session.outputs:
        try:
            staged = _session.outputs.get(_target(Path(path)))
        except (OSError, ValueError):
            staged = None
        if staged is not None:
            return staged.temp
    return Path(path)


def output_folder(path: str | os.PathLike, names: Iterable[str] = ()) -> Path:
    """Check an output folder up front, so a long run fails before it starts, not after: it is a
    folder or can be made one (the nearest existing folder above it is writable), and none of the
    files `names` it will hold is a link or an input read so far. Nothing is created here: the
    folder appears when the command's outputs are committed (`command_files`)."""
    folder = Path(path)
    if exists(folder) and not is_dir(folder):
        raise InputError(f"{folder}: is a file, not a folder")
    existing = _resolved(folder)
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise InputError(f"{folder}: cannot create output folder: {existing} is a file")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise InputError(f"{folder}: output folder is not writable" if existing == _resolved(folder)
                         else f"{folder}: cannot create output folder: {existing} is not writable")
    if _session is not None:
        for name in names:
            _check_target(_target(folder / name), str(folder / name), "output", _session)
    return folder
