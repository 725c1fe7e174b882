"""Measured data in: a rig's file → a reference trace for `emaphm.identify` (next-features §D).

The pipeline, one module per step:

- `channel_map` — `ChannelMap`: which column is which signal, in which unit (a TOML file);
- `formats` — readers chosen by content: CSV, HDF5 (emaphm traces too), MATLAB ``.mat`` v4/v5/
  v7.3 (Paderborn-style struct of channels included), Parquet (optional pyarrow);
- `measurement` — `load_measurement`: the mapped channels in SI, each on its own time axis;
- `timebase` — clean segments common to all channels (NaN runs and gaps split the record);
- `alignment` — phase currents + rotor angle → i_q (Clarke/Park of `kernels.transforms`, angle
  offset θ0 estimated from i_d = 0, its sign from the motion);
- `checks` — `plausibility`: unit mistakes and corrupt samples, caught with a hint;
- `reference` — `to_reference` (the trace on the model grid, anti-aliased) and `write_reference`;
- `inspection` — `inspect_file`: what a file holds and whether it is usable.

Example::

    from emaphm.measured import ChannelMap, load_measurement, to_reference, write_reference

    meas = load_measurement("rig.csv", ChannelMap.load("rig.toml"))
    ref = to_reference(meas)              # ref.report: θ0, segments, resampling, warnings
    write_reference(ref, "ref.h5")        # then: emaphm identify --reference ref.h5

Every malformed input raises `emaphm.InputError` with one line naming the file and the channel or
row; the command line turns it into exit status 2.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_names

# public name -> module that defines it: imported on first use (PEP 562), so that a module that
# needs one submodule (`limits`, `grid`) does not load the readers, the alignment's scipy.optimize
# and the rest (0.2 s of every ``emaphm identify``)
_LAZY = {
    "ChannelMap": "channel_map", "ChannelSpec": "channel_map", "plausibility": "checks",
    "inspect_file": "inspection", "Channel": "measurement", "Measurement": "measurement",
    "load_measurement": "measurement", "Reference": "reference", "to_reference": "reference",
    "write_reference": "reference",
}  # fmt: skip
__getattr__, __dir__ = lazy_names(__name__, _LAZY, globals())

if TYPE_CHECKING:
    from .channel_map import ChannelMap, ChannelSpec
    from .checks import plausibility
    from .inspection import inspect_file
    from .measurement import Channel, Measurement, load_measurement
    from .reference import Reference, to_reference, write_reference

__all__ = [
    "Channel",
    "ChannelMap",
    "ChannelSpec",
    "Measurement",
    "Reference",
    "inspect_file",
    "load_measurement",
    "plausibility",
    "to_reference",
    "write_reference",
]
