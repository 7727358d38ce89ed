"""Result of one simulation: time histories, events, failure, energy, summary."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from shipblock.equations import I_TH_DD, I_XB_DD, I_XS_DD, N_SOLVE_OUT, solve_mode
from shipblock.modes import FAILURE_NAMES, MODE_DESCRIPTIONS, MODE_FLAGS, EventKind

#: A rate too small to change any force (its square is 0), whose sign gives the pivot.
_PIVOT_RATE = np.nextafter(0.0, 1.0)


def _with_pivot(mode, theta, theta_dot, v_b, v_s, system, ax, ay):
    r"""``theta_dot`` with the pivot marked where the blocks rock from theta = theta_dot = 0.

    The forces of a rocking mode depend on its pivot ``s``, which the histories give as the
    sign of theta, or of theta_dot where theta is 0. At a sample where the blocks rock with
    neither (a rocking phase starting at the sample, e.g. at t = 0), the pivot is the one on
    which the rotation starts, :math:`s\ddot\theta > 0` (the mode selection admits a new
    rocking only so; of the two pivots at most one can), with each slip direction at zero
    velocity the one its acceleration takes. It is carried to the force computation as the sign
    of ``_PIVOT_RATE``. Before 2026-11-26 it was taken as +1 whatever the direction (issue 32:
    a ship friction utilisation of 4.55 reported at t = 0 where it was 0.64). Where neither
    pivot starts the rotation (not met), +1 is kept.
    """
    rocking = MODE_FLAGS[np.clip(mode, 0, 8), 1] != 0
    at_zero = rocking & (theta == 0.0) & (theta_dot == 0.0)
    if not at_zero.any():
        return theta_dot
    out = np.array(theta_dot, dtype=float)
    p = system.to_parameter_vector()
    w = np.empty(N_SOLVE_OUT)
    for k in np.flatnonzero(at_zero):
        slip1, slip2 = int(MODE_FLAGS[mode[k], 0]), int(MODE_FLAGS[mode[k], 2])
        starting = set()
        for s in (1.0, -1.0):
            for sig1 in ((np.sign(v_b[k]),) if v_b[k] != 0.0 else (1.0, -1.0)):
                for sig2 in ((np.sign(v_s[k]),) if v_s[k] != 0.0 else (1.0, -1.0)):
                    if (solve_mode(p, slip1, 1, slip2, s, sig1, sig2, 0.0, 0.0, ax[k],
                                   system.g + ay[k], w)
                            and s * w[I_TH_DD] > 0.0
                            and (not slip1 or v_b[k] != 0.0 or sig1 * w[I_XB_DD] > 0.0)
                            and (not slip2 or v_s[k] != 0.0 or sig2 * w[I_XS_DD] > 0.0)):
                        starting.add(s)
        if len(starting) == 1:
            out[k] = starting.pop() * _PIVOT_RATE
    return out


@dataclass(frozen=True)
class Event:
    """One located event.

    Attributes
    ----------
    time : float
        Time of the event [s], located to about 1e-12 s.
    kind : str
        What happened (an :class:`~shipblock.modes.EventKind` name in lower case, for example
        ``"uplift"``, ``"impact"``, ``"ground_slip_start"``, ``"overturning"``).
    from_mode, to_mode : int
        Mode before and after (0 after a failure).
    """

    time: float
    kind: str
    from_mode: int
    to_mode: int


class EventLog(Sequence):
    """The located events of a run, as a read-only sequence of :class:`Event`.

    Holds the kernel's event arrays and builds an :class:`Event` only when one is looked at,
    so runs with thousands of stick-slip events cost no Python objects until they are used.

    Parameters
    ----------
    time : ndarray
        Event times [s].
    kind, from_mode, to_mode : ndarray of int
        Event codes (:class:`~shipblock.modes.EventKind`) and modes before and after.
    """

    def __init__(self, time, kind, from_mode, to_mode):
        self.time = np.asarray(time, dtype=float)
        self.kind_code = np.asarray(kind, dtype=np.int64)
        self.from_mode = np.asarray(from_mode, dtype=np.int64)
        self.to_mode = np.asarray(to_mode, dtype=np.int64)

    def __len__(self) -> int:
        return self.time.size

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        return Event(float(self.time[index]), _KIND_NAMES[int(self.kind_code[index])],
                     int(self.from_mode[index]), int(self.to_mode[index]))

    @property
    def kinds(self) -> np.ndarray:
        """Event kind names as an array of str."""
        return np.array([_KIND_NAMES[int(k)] for k in self.kind_code], dtype=str)

    def __repr__(self) -> str:
        return f"EventLog({list(self)!r})"


@dataclass(frozen=True)
class Energy:
    """Energy bookkeeping at the input samples [J].

    The balance :math:`T + V - (T_0 + V_0) = W_{in} - D - E_{imp}` holds to the integration
    accuracy; :attr:`residual` is its left side minus its right side.

    Attributes
    ----------
    input_work : ndarray
        Work of the inertial forces of the ground motion, :math:`\\int -(a P_x + \\ddot y_g P_y)\\,dt`.
    kinetic : ndarray
        Kinetic energy relative to the ground :math:`T`.
    potential : ndarray
        Gravity potential above the rest position :math:`V = (nm+2M) g R (\\cos\\varphi - \\cos\\theta_c)`.
    friction : ndarray
        Energy dissipated by friction :math:`D = \\int -(f_x\\dot x_b + F_x\\dot x_s)\\,dt`.
    impact : ndarray
        Kinetic energy lost in impacts :math:`E_{imp}`.
    """

    input_work: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    friction: np.ndarray
    impact: np.ndarray

    @property
    def residual(self) -> np.ndarray:
        """Energy-balance residual at the samples [J]."""
        mech = self.kinetic + self.potential
        return (mech - mech[0]) - (self.input_work - self.friction - self.impact)


@dataclass(frozen=True)
class SimulationResult:
    """Response of the ship-block system to one ground motion.

    All arrays are at the input samples ``t_k = k dt``; after a failure they are NaN and
    ``mode`` is 0.

    Attributes
    ----------
    time : ndarray
        Sample times [s].
    x_b, theta, x_s : ndarray
        Block slip relative to the ground [m], block rotation (counter-clockwise) [rad], ship slip
        relative to the blocks [m].
    v_b, theta_dot, v_s : ndarray
        Their rates [m/s, rad/s, m/s].
    mode : ndarray of int
        Active mode (paper numbering 1..8) at each sample.
    events : sequence of Event
        Every located event, in time order (the first is the start); an :class:`EventLog`.
    failure : str or None
        ``None``, ``"separation"``, ``"overturning"`` or ``"solver_error"``.
    failure_time : float or None
        Time of the failure [s].
    energy : Energy
        Energy bookkeeping.
    summary : dict
        Peak and residual displacements, time per mode, number of impacts, etc.
    system : ShipBlockSystem
        The system simulated.
    ground_acceleration : tuple of ndarray
        ``(ax, ay)`` as used (scaled) [m/s^2].
    """

    time: np.ndarray
    x_b: np.ndarray
    theta: np.ndarray
    x_s: np.ndarray
    v_b: np.ndarray
    theta_dot: np.ndarray
    v_s: np.ndarray
    mode: np.ndarray
    events: Sequence
    failure: str | None
    failure_time: float | None
    energy: Energy
    summary: dict
    system: object
    ground_acceleration: tuple = field(repr=False)
    options: dict = field(default_factory=dict, repr=False)

    @property
    def dt(self) -> float:
        """Sample interval [s]."""
        return float(self.time[1] - self.time[0]) if self.time.size > 1 else 0.0

    def __repr__(self) -> str:
        """One line: duration, samples, failure and peaks (not the arrays, which ``to_dataset``
        and the attributes give)."""
        s = self.summary
        n = self.time.size
        duration = float(self.time[-1] - self.time[0]) if n else 0.0
        failure = ("none" if self.failure is None
                   else f"{self.failure} at t = {self.failure_time:.4g} s")
        peaks = []
        for key, label, factor, unit in (("peak_block_slip", "x_b", 100.0, "cm"),
                                         ("peak_rotation", "theta", 1000.0, "mrad"),
                                         ("peak_ship_slip", "x_s", 100.0, "cm")):
            if key in s:
                peaks.append(f"|{label}| {factor * float(s[key]):.4g} {unit}")
        peak_text = f", peaks {', '.join(peaks)}" if peaks else ""
        impacts = f", {int(s['n_impacts'])} impacts" if "n_impacts" in s else ""
        return (f"SimulationResult({duration:.4g} s, {n} samples at dt = {self.dt:.4g} s, "
                f"failure {failure}{peak_text}{impacts}, {len(self.events)} events)")

    def events_of(self, kind: str) -> list:
        """The events of one kind (for example ``"impact"``)."""
        return [e for e in self.events if e.kind == kind]

    @cached_property
    def forces(self):
        """Interface forces per block at the samples (:class:`shipblock.interface_forces.InterfaceForces`).

        Computed on first use from the stored state and input; their peaks between the samples
        are in :attr:`summary` (``peak_ground_normal_force`` ..., :mod:`shipblock.interface_forces`).
        """
        from shipblock.interface_forces import interface_forces

        ax, ay = self.ground_acceleration
        return interface_forces(self.system, self.mode, self.theta,
                                _with_pivot(self.mode, self.theta, self.theta_dot, self.v_b,
                                            self.v_s, self.system, ax, ay),
                                self.v_b, self.v_s, ax, ay)

    def to_dataset(self):
        """The result as an :class:`xarray.Dataset` with units and long names.

        Returns
        -------
        xarray.Dataset
            Dimension ``time`` for the histories and ``event`` for the event log; the system
            parameters, failure and summary are global attributes.
        """
        import xarray as xr

        from shipblock.version import __version__

        def var(values, units, long_name, dims=("time",)):
            return xr.Variable(dims, values, attrs={"units": units, "long_name": long_name})

        ax, ay = self.ground_acceleration
        events = self.events
        ds = xr.Dataset(
            {
                "ground_acceleration_h": var(ax, "m/s^2", "horizontal ground acceleration"),
                "ground_acceleration_v": var(ay, "m/s^2", "vertical ground acceleration"),
                "x_b": var(self.x_b, "m", "block slip relative to the ground"),
                "theta": var(self.theta, "rad", "block rotation, counter-clockwise"),
                "x_s": var(self.x_s, "m", "ship slip relative to the blocks"),
                "v_b": var(self.v_b, "m/s", "block slip velocity"),
                "theta_dot": var(self.theta_dot, "rad/s", "block angular velocity"),
                "v_s": var(self.v_s, "m/s", "ship slip velocity relative to the blocks"),
                "mode": var(self.mode.astype(np.int8), "1", "mode of motion (paper numbering, 0 = stopped)"),
                "input_work": var(self.energy.input_work, "J", "work of the ground motion"),
                "kinetic_energy": var(self.energy.kinetic, "J", "kinetic energy relative to the ground"),
                "potential_energy": var(self.energy.potential, "J", "gravity potential energy"),
                "friction_dissipation": var(self.energy.friction, "J", "energy dissipated by friction"),
                "impact_loss": var(self.energy.impact, "J", "kinetic energy lost in impacts"),
                **self._force_variables(var),
                "event_time": var(np.array([e.time for e in events], dtype=float), "s",
                                  "event time", ("event",)),
                "event_kind": var(np.array([e.kind for e in events], dtype=str), "1",
                                  "event kind", ("event",)),
                "event_from_mode": var(np.array([e.from_mode for e in events], dtype=np.int8),
                                       "1", "mode before the event", ("event",)),
                "event_to_mode": var(np.array([e.to_mode for e in events], dtype=np.int8), "1",
                                     "mode after the event", ("event",)),
            },
            coords={"time": ("time", self.time, {"units": "s", "long_name": "time"})},
        )
        ds["mode"].attrs["flag_values"] = np.arange(9, dtype=np.int8)
        ds["mode"].attrs["flag_meanings"] = " ".join(
            MODE_DESCRIPTIONS[m].replace(" ", "_").replace(",", "") for m in range(9)
        )
        ds.attrs["title"] = "shipblock simulation"
        ds.attrs["shipblock_version"] = __version__
        ds.attrs["failure"] = self.failure or "none"
        ds.attrs["failure_time_s"] = np.nan if self.failure_time is None else self.failure_time
        for key, value in self.system.to_dict().items():
            ds.attrs[f"system_{key}"] = "None" if value is None else value
        ds.attrs["restitution_used"] = self.system.effective_restitution
        for key, value in self.summary.items():
            if np.isscalar(value) and not isinstance(value, str):
                ds.attrs[f"summary_{key}"] = float(value)
        for key, value in self.options.items():
            ds.attrs[f"solver_{key}"] = value
        return ds


    def _force_variables(self, var) -> dict:
        """The interface forces per block as dataset variables (see :attr:`forces`)."""
        f = self.forces
        return {
            "ground_normal_force": var(f.ground_normal, "N",
                                       "normal force of the dock floor on one block"),
            "ground_friction_force": var(f.ground_friction, "N", "friction force of the dock "
                                                                  "floor on one block, positive "
                                                                  "to the right"),
            "ship_normal_force": var(f.ship_normal, "N", "normal force of one block on the ship"),
            "ship_friction_force": var(f.ship_friction, "N", "friction force of one block on "
                                                              "the ship, positive to the right"),
            "ground_friction_utilisation": var(f.ground_utilisation, "1",
                                               "|f_x| / (mu_s f_y), blocks on the floor"),
            "ship_friction_utilisation": var(f.ship_utilisation, "1",
                                             "|F_x| / (mu_s F_y), ship on the blocks"),
        }


_KIND_NAMES = {k.value: k.name.lower() for k in EventKind}


def event_kind_name(code: int) -> str:
    """Lower-case name of an event code."""
    return _KIND_NAMES[int(code)]


def failure_name(code: int) -> str | None:
    """Failure name of a failure code (None for 0)."""
    return FAILURE_NAMES[int(code)]
