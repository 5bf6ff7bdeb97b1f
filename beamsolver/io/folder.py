"""The output folder of a run: created and checked writable; files written atomically."""
import os
import tempfile
from pathlib import Path

from ..errors import InputError
from ..results.files import follow_umask

__all__ = ["atomic", "output_folder"]


def atomic(path, write):
    """Call ``write(tmp_path)`` then rename ``tmp_path`` to ``path``; a failing file system
    (full disk, permissions) raises ``InputError`` naming the folder and the file."""
    path = Path(path)
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".tmp" + path.suffix, dir=path.parent)
        follow_umask(fd)
        os.close(fd)
        write(tmp)
        os.replace(tmp, path)
        tmp = None
    except OSError as e:
        raise InputError(f"output folder {str(path.parent)!r}: cannot write {path.name} "
                         f"({e.strerror or e})") from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)


def output_folder(folder):
    """``folder`` created if missing and checked writable (a probe file is written and removed)."""
    folder = Path(folder)
    for p in (folder, *folder.parents):
        if p.exists():
            if not p.is_dir():
                raise InputError(f"output {str(folder)!r}: {str(p)!r} is a file, not a folder")
            break
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(f"output folder {str(folder)!r}: cannot create it ({e.strerror or e})") from None
    atomic(folder / ".write-test", lambda tmp: None)
    try:
        os.unlink(folder / ".write-test")
    except OSError as e:
        raise InputError(f"output folder {str(folder)!r}: cannot write ({e.strerror or e})") from None
    return folder
