"""Atomic file placement: a file written under a temporary name in its folder, then put at its
path in one step, so that a crash never leaves half a file and two processes never both believe
they wrote it; a writer that lost the race, or whose disk filled up, keeps its file elsewhere and
is told where. The results files (format.py) and the sweep's dataset are placed so."""
from __future__ import annotations

import errno
import os
import re
import secrets
import tempfile
from pathlib import Path
from typing import Callable


class ResultsSavedElsewhere(OSError):
    """The results could not be placed at the path asked for (another process made that file
    meanwhile, or its disk is full); they were kept at `kept`, which the message names."""

    def __init__(self, wanted: Path, kept: Path, reason: str) -> None:
        super().__init__(f"{wanted}: {reason}; the results were kept in {kept} instead")
        self.wanted, self.kept, self.reason = wanted, kept, reason


# temporary files are `.<name>.oceanmc-<pid>-<token>.tmp`: recognisably oceanmc's, and the pid
# tells whether their writer is still alive (a SIGKILLed checkpoint leaves one behind)
_TEMP_NAME = re.compile(r"^\.(?P<name>.+)\.oceanmc-(?P<pid>\d+)-[0-9a-f]+\.tmp$")
_NO_SPACE = (errno.ENOSPC, errno.EDQUOT)


def _temp_path(path: Path) -> Path:
    return path.with_name(f".{path.name}.oceanmc-{os.getpid()}-{secrets.token_hex(4)}.tmp")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's live process
        return True
    return True


def remove_stale_temps(path: Path) -> None:
    """Removes the temporary files of `path` left by oceanmc writers that are no longer alive;
    never those of a live process (this one's included: another thread may be writing)."""
    folder = path.parent if str(path.parent) else Path(".")
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        match = _TEMP_NAME.match(entry.name)
        if match and match["name"] == path.name and not _alive(int(match["pid"])):
            Path(entry.path).unlink(missing_ok=True)


def place_atomically(path: str | Path, write: Callable[[Path], None],
                     overwrite: bool = True) -> Path:
    """Writes a file with write(tmp) under a temporary name in the same folder, then puts it at
    `path` in one step: os.replace if overwrite, else os.link, which fails if `path` exists, so
    that two processes never both believe they wrote it. The one that lost keeps its file at
    `<stem>.<pid>[.n]<suffix>` and is told so (ResultsSavedElsewhere), as is a writer whose disk
    filled up (its file goes to the system temporary folder, else the current folder)."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    folder.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(path)
    tmp = _temp_path(path)
    try:
        try:
            _write_temp(tmp, write)
        except OSError as exc:
            if exc.errno not in _NO_SPACE and "No space left" not in str(exc):
                raise
            Path(tmp).unlink(missing_ok=True)
            kept = _write_fallback(path, write)
            raise ResultsSavedElsewhere(path, kept, f"no space left on {folder}") from None
        if overwrite:
            os.replace(tmp, path)
            return path
        try:
            os.link(tmp, path)
            return path
        except FileExistsError:
            kept = _link_free_name(tmp, path)
            raise ResultsSavedElsewhere(
                path, kept, "another process created this file while this one was running "
                "(pass --overwrite to replace it)") from None
    finally:
        tmp.unlink(missing_ok=True)


def _write_temp(tmp: Path, write: Callable[[Path], None]) -> None:
    with open(tmp, "xb"):  # claims the name; the writer reopens it
        pass
    write(tmp)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)


def _link_free_name(tmp: Path, path: Path) -> Path:
    """Links tmp to the first free name `<stem>.<pid>[.n]<suffix>` beside path."""
    for n in range(1000):
        kept = path.with_name(f"{path.stem}.{os.getpid()}{f'.{n}' if n else ''}{path.suffix}")
        try:
            os.link(tmp, kept)
            return kept
        except FileExistsError:
            continue
    raise FileExistsError(f"{path}: no free name to keep the results under")


def _write_fallback(path: Path, write: Callable[[Path], None]) -> Path:
    """Writes the file in the system temporary folder, else the current folder."""
    for folder in (Path(tempfile.gettempdir()), Path.cwd()):
        tmp = _temp_path(folder / path.name)
        try:
            _write_temp(tmp, write)
            return _link_free_name(tmp, folder / path.name)
        except OSError:
            continue
        finally:
            tmp.unlink(missing_ok=True)
    raise OSError(errno.ENOSPC, f"{path}: no space left there, nor in "
                  f"{tempfile.gettempdir()} or {Path.cwd()}; the results are lost")
