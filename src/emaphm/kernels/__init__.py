"""Numba kernels: the equations, and nothing else.

Pure functions of floats, arrays and `NamedTuple` parameter packs whose field names are the
paper's symbols. This sub-package imports nothing from the rest of emaphm; the API layer
(`emaphm.models`: `hf.py`, `lf.py`) validates input, packs parameters and calls these kernels.

Layout (the block diagram): `controller` (ACE position PID), `pmsm_abc` (hysteresis inverter and
three-phase stator), `mechanics` (gearbox, friction, backlash, end-stops), `sensors` (ADC),
`transforms` (Clarke–Park), `hf_twin` (the one fixed-step loop of the high-fidelity twin),
`monitor` (the low-fidelity monitor's loop and its population twin), `fitness` (eq. 3 fused with
the monitor's population run and the comparison filter), `batches` (how a population's rows are
shared among the threads); `_jit` is the one njit helper.
"""
