"""The output directory of a run, all or nothing.

A run writes into a staging directory beside ``--out`` (``.<name>.staging-<pid>-<random>``) and
swaps it into place only when every file (records, truth, results, report) is complete: with
Linux's ``renameat2(RENAME_EXCHANGE)`` the old and the new directory trade places in one atomic
step, elsewhere by two renames. A failed, interrupted or killed run leaves the previous contents
of ``--out`` as they were; staging directories that a killed run left behind are removed by the
next run. Files and directories get the user's umask.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import os
import shutil
import tempfile
from pathlib import Path

from vtrials.errors import InputError

_STAGE = ".staging-"
_OLD = ".replaced-"


def umask() -> int:
    """The process's umask (read without changing it for longer than the call)."""
    m = os.umask(0o022)
    os.umask(m)
    return m


def check_out(out: str | Path) -> Path:
    """Check ``--out`` before anything runs: it must be a directory or not exist yet, and the
    nearest existing folder above it must be a writable directory."""
    name = str(out)
    if not name or "\x00" in name:
        raise InputError("--out", "", f"{name!r} is not a directory name")
    p = Path(out)
    if p.name in ("", ".", ".."):
        p = p.resolve()
    if p.parent == p:
        raise InputError(name, "--out", "the root directory cannot be replaced; give a directory below it")
    try:
        if p.exists() and not p.is_dir():
            raise InputError(name, "--out", "exists and is not a directory")
        anc = p.parent
        while not anc.exists():
            if anc.is_symlink():
                raise InputError(name, "--out", f"{anc} is a dangling link")
            anc = anc.parent
        if not anc.is_dir():
            raise InputError(name, "--out", f"{anc} is not a directory")
        if not os.access(anc, os.W_OK | os.X_OK):
            raise InputError(name, "--out", f"cannot write in {anc} (permission denied)")
        if p.exists() and not os.access(p, os.W_OK | os.X_OK):
            raise InputError(name, "--out", "the directory is not writable (permission denied)")
        if p.exists():
            here = Path.cwd().resolve()
            if p.resolve() == here or p.resolve() in here.parents:
                raise InputError(name, "--out", "is the working directory or holds it; the run replaces --out "
                                                "whole: give a directory of its own")
            foreign = sorted(x.name for x in p.iterdir() if not _is_output(x))
            if foreign:
                raise InputError(name, "--out", f"holds files that are not a vtrials output ({', '.join(foreign[:3])}"
                                                f"{', …' if len(foreign) > 3 else ''}); the run replaces --out whole: "
                                                f"give an empty or new directory, or a previous run's")
    except OSError as exc:
        raise InputError(name, "--out", f"cannot use this directory ({exc.strerror})") from None
    return p


OUTPUT_NAMES = ("results.json", "truth.nc", "records", "report.md", "trajectory.png", "identification.json")


def _is_output(x: Path) -> bool:
    """An entry a vtrials run writes into --out (so a directory of such entries may be replaced)."""
    return x.name in OUTPUT_NAMES or (x.suffix == ".png" and x.is_file())


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def clean_stale(out: Path) -> None:
    """Remove staging and replaced directories of ``out`` whose run is no longer alive."""
    parent = out.parent
    if not parent.is_dir():
        return
    for kind in (_OLD, _STAGE):
        for d in sorted(parent.glob(f".{out.name}{kind}*")):
            try:
                pid = int(d.name[len(out.name) + 1 + len(kind):].split("-", 1)[0])
            except ValueError:
                continue
            if pid == os.getpid() or _alive(pid):
                continue
            if kind == _OLD and not out.exists():  # killed between the two renames: restore the old run
                os.rename(d, out)
            else:
                shutil.rmtree(d, ignore_errors=True)


_libc = None


def _exchange(a: Path, b: Path) -> bool:
    """Swap two directories atomically (Linux renameat2 RENAME_EXCHANGE); False if unsupported."""
    global _libc
    if _libc is None:
        try:
            _libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            _libc.renameat2  # noqa: B018 — present in glibc ≥ 2.28
        except (OSError, AttributeError):
            _libc = False
    if not _libc:
        return False
    at_fdcwd, rename_exchange = -100, 2
    r = _libc.renameat2(at_fdcwd, os.fsencode(str(a)), at_fdcwd, os.fsencode(str(b)), rename_exchange)
    if r == 0:
        return True
    err = ctypes.get_errno()
    if err in (22, 38, 95):  # EINVAL, ENOSYS, EOPNOTSUPP: the file system cannot exchange
        return False
    raise OSError(err, os.strerror(err), str(b))


def _mode_tree(root: Path, mask: int) -> None:
    """Give the staged files and directories the user's umask (temporary files are made 0600)."""
    os.chmod(root, 0o777 & ~mask)
    for d, dirs, files in os.walk(root):
        for x in dirs:
            os.chmod(os.path.join(d, x), 0o777 & ~mask)
        for x in files:
            os.chmod(os.path.join(d, x), 0o666 & ~mask)


@contextlib.contextmanager
def staged_output(out: str | Path):
    """Yield a fresh staging directory beside ``out``; on success it replaces ``out`` whole.

    On any exception (KeyboardInterrupt included) the staging directory is removed and ``out`` is
    left as it was.
    """
    out = check_out(out)
    name = str(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        clean_stale(out)
        stage = Path(tempfile.mkdtemp(prefix=f".{out.name}{_STAGE}{os.getpid()}-", dir=out.parent))
    except OSError as exc:
        raise InputError(name, "--out", f"cannot create the output beside it ({exc.strerror})") from None
    try:
        yield stage
        _mode_tree(stage, umask())
        if not out.exists():
            os.rename(stage, out)
        elif _exchange(stage, out):
            shutil.rmtree(stage, ignore_errors=True)  # now the previous run
        else:  # two renames: a kill between them leaves the previous run as .<name>.replaced-…
            old = Path(tempfile.mkdtemp(prefix=f".{out.name}{_OLD}{os.getpid()}-", dir=out.parent))
            os.rmdir(old)
            os.rename(out, old)
            os.rename(stage, out)
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
