"""Executes a notebook as a user would (a fresh kernel, its own folder as the working
directory) and fails on the first cell that raises: `python scripts/run_notebook.py NB...`."""

import sys
from pathlib import Path

import nbclient
import nbformat

for name in sys.argv[1:]:
    path = Path(name).resolve()
    notebook = nbformat.read(path, as_version=4)
    nbclient.NotebookClient(
        notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(path.parent)}}
    ).execute()
    print(f"{name}: {len(notebook.cells)} cells executed")
