"""Tables kept on disk beside the compile cache (the cap tables, scene/estimates.py; the rough
sea's table, scene/surface_table.py): written whole or not at all."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np


def save_atomically(path: Path, table: np.ndarray) -> bool:
    """Writes `table` to `path` (.npy) through a temporary file in the same folder and a rename,
    so that a concurrent run never reads half a file. False, and nothing left behind, where the
    folder cannot be written (a read-only install: the table is then computed in each
    process)."""
    temporary = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path.parent, prefix=f".{path.stem}.",
                                         suffix=".tmp", delete=False) as out:
            temporary = out.name
            np.save(out, table)
        os.replace(temporary, path)
        return True
    except OSError:
        if temporary is not None:
            Path(temporary).unlink(missing_ok=True)
        return False
