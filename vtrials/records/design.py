"""Reading the trials team's own model files (e.g. the design-stage RAO model of models/<ship>/design/).

These are documents the team brings to the trial, not simulator output: the reductions may read them
(through this module, like records). A truth file is refused.
"""

from __future__ import annotations

from pathlib import Path

import h5netcdf
import numpy as np

from vtrials.errors import InputError
from vtrials.records.netcdf import _plain


def read_team_model(path: str | Path) -> tuple[dict, dict]:
    """(variables {name: numpy array}, global attributes) of a team model file (netCDF4)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(str(path), "", "team model file not found")
    with h5netcdf.File(path, "r") as f:
        attrs = {k: _plain(v) for k, v in f.attrs.items()}
        if attrs.get("content") == "truth":
            raise InputError(str(path), "content", f"{attrs.get('content')!r}: a truth file is not a team model")
        data = {k: np.asarray(v[:]) for k, v in f.variables.items()}
    return data, attrs
