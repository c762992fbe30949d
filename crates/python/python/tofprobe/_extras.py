"""Optional dependencies, imported where a call needs them: a missing one is an
``ImportError`` naming the extra that installs it (``pip install "tofprobe[dask]"``)."""

from __future__ import annotations

import importlib
from types import ModuleType

#: The extras of pyproject.toml and the module each provides.
EXTRAS = {"dask": "distributed", "plot": "matplotlib", "slurm": "dask_jobqueue",
          "progress": "tqdm"}


def require(extra: str, what: str) -> ModuleType:
    """The module of ``extra``, or an ImportError saying ``what`` needs it and how to get it."""
    module = EXTRAS[extra]
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(
            f"{what} needs {module.split('.')[0]}, which is not installed: "
            f'pip install "tofprobe[{extra}]"'
        ) from e
