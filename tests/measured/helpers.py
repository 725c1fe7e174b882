"""Writers of synthetic measured files in the layouts real rigs and tools produce (tests only)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

import emaphm
from emaphm.measured import ChannelMap

# the twin's signals in SI; the map of a file that stores them as they are
SI_ROLES = ("theta_cmd", "theta_u", "i_q")


def si_map(**changes: Any) -> dict[str, Any]:
    """{"channels": ...} for columns named as the signals, in SI; `changes` replace entries (None drops)."""
    channels: dict[str, Any] = {"t": {"name": "t", "unit": "s"}}
    channels.update({r: {"name": r, "unit": "A" if r.startswith("i") else "rad"} for r in SI_ROLES})
    for role, entry in changes.items():
        if entry is None:
            channels.pop(role, None)
        else:
            channels[role] = entry
    return {"channels": channels}


def cmap(data: Mapping[str, Any]) -> ChannelMap:
    return ChannelMap.from_dict(data, where="test map")


def write_csv(
    path: Path,
    columns: Mapping[str, Sequence[Any] | np.ndarray],
    *,
    delimiter: str = ",",
    units: Sequence[str] | None = None,
) -> Path:
    """A CSV with a header row (and optionally a units row); cells as given (numbers with 17 digits)."""
    names = list(columns)
    n = len(next(iter(columns.values())))
    lines = [delimiter.join(names)]
    if units is not None:
        lines.append(delimiter.join(units))
    cols = [np.asarray(columns[k], dtype=object) for k in names]
    for i in range(n):
        lines.append(delimiter.join(f"{c[i]:.17g}" if isinstance(c[i], float) else str(c[i]) for c in cols))
    path.write_text("\n".join(lines) + "\n")
    return path


def write_mat73(path: Path, variables: Mapping[str, Any]) -> Path:
    """A MATLAB v7.3 file as MATLAB writes it: a 512-byte text header (user block) then HDF5;
    vectors stored transposed (n×1 → a 1×n dataset), text as uint16 with MATLAB_class "char",
    a struct (a dict here) as a group with MATLAB_class "struct"."""
    import h5py

    def put(group: Any, name: str, value: Any) -> None:
        if isinstance(value, dict):
            sub = group.create_group(name)
            sub.attrs["MATLAB_class"] = np.bytes_("struct")
            for key, v in value.items():
                put(sub, key, v)
        elif isinstance(value, str):
            ds = group.create_dataset(name, data=np.array([[ord(c)] for c in value], dtype=np.uint16))
            ds.attrs["MATLAB_class"] = np.bytes_("char")
        else:
            arr = np.asarray(value, dtype=np.float64).reshape(-1, 1)  # a MATLAB column vector n×1
            ds = group.create_dataset(name, data=arr.T)  # ... stored transposed
            ds.attrs["MATLAB_class"] = np.bytes_("double")

    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in variables.items():
            put(f, name, value)
    header = (
        b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
    )
    with path.open("r+b") as fh:
        fh.write(header.ljust(116) + b"\0" * 8 + b"\x00\x02IM")
    return path


def write_paderborn(
    path: Path, stem: str, rasters: Mapping[str, np.ndarray], channels: Sequence[tuple[str, str, np.ndarray]]
) -> Path:
    """A Paderborn-KAt-like .mat v5: struct `stem` with X (Name, Type, Data = times, Unit, Raster)
    and Y (Name, Type, Data, Unit, Raster, ...) and Info/Description text."""
    from scipy.io import savemat

    X = np.array(
        [{"Name": "", "Type": 4, "Data": t, "Unit": "", "Raster": name} for name, t in rasters.items()],
        dtype=object,
    )
    Y = np.array(
        [
            {
                "Name": name,
                "Type": 4,
                "Data": data,
                "Unit": "",
                "Raster": raster,
                "Device": "Platform",
                "DownSampling": 1,
            }
            for name, raster, data in channels
        ],
        dtype=object,
    )
    savemat(path, {stem: {"Info": "synthetic", "X": X, "Y": Y, "Description": "test rig"}})
    return path


def twin_columns(r: emaphm.SimResult, stop: int | None = None) -> dict[str, np.ndarray]:
    """The twin's signals a rig would log, in SI, cut to `stop` samples."""
    names = ("t", "theta_cmd", "theta_u", "i_q", "i_a", "i_b", "i_c", "theta_e")
    return {n: np.array(r[n][:stop], dtype=np.float64) for n in names}


def close(a: np.ndarray, b: np.ndarray, rel: float = 1e-9) -> bool:
    """max |a − b| within `rel` of max |b| (the scale of the signal)."""
    return bool(np.max(np.abs(np.asarray(a) - np.asarray(b))) <= rel * np.max(np.abs(b)))
