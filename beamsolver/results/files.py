"""File-system helpers of the writers: permissions of new files, the previous run's numbered files.

``tempfile.mkstemp`` creates files with mode ``0600`` whatever the umask;
``follow_umask`` gives them the mode ``open()`` would have (``0666 & ~umask``),
so others in a group can open the ParaView files and saved results.
"""
import os
import re
from pathlib import Path

__all__ = ["follow_umask", "previous_series"]


def _umask():
    mask = os.umask(0o022)     # the umask can only be read by setting it
    os.umask(mask)
    return mask


def follow_umask(fd):
    """Set the mode of the open file ``fd`` to ``0666 & ~umask`` (as ``open()`` creates files)."""
    os.fchmod(fd, 0o666 & ~_umask())


def previous_series(folder, collections, pattern):
    """Files listed by the ``.pvd`` ``collections`` in ``folder`` whose names match ``pattern``.

    Used to remove the numbered files of a previous run before a new one writes the
    same series: only files a collection of ours lists, with our naming, in
    ``folder`` itself (no paths) are returned.
    """
    folder = Path(folder)
    rx = re.compile(pattern)
    found = []
    for name in collections:
        pvd = folder / name
        if not pvd.is_file():
            continue
        text = pvd.read_text(errors="replace")
        for f in re.findall(r'file="([^"]*)"', text):
            if rx.fullmatch(f) and (folder / f).is_file():
                found.append(folder / f)
    return found
