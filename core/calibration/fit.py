"""The model fitted to a van's measured trips: bounded nonlinear least squares of the
simulated against the measured power (``scipy.optimize.least_squares``), through the same
simulation the plans use (:func:`core.physics.simulate.simulate`).

The paper's model "uses a minimum number of parameters for an easy fit": the drag area, the
rolling resistance, the drive train's efficiency motoring and regenerating (eqs. 2–7), the
auxiliaries' draw, and — when the refrigeration is measured — the box walls' heat transfer and
the unit's COP (§2.4). Each trip is resampled to a uniform step (the simulation's), and the
measured power is compared with each step's mean simulated power, per measured channel, each
channel weighted by its own spread so that a watt of the cab counts as much as a watt of the
drive train relative to what each varies by.

Uncertainty is a sandwich at the solution: the Jacobian's ``(JᵀJ)⁻¹`` around the long-run
covariance of the residuals' scores (Newey–West within each measured series), so that noise
which grows with the power and is correlated in time — what telematics logs carry — does not
make the intervals too narrow; the 95 % interval uses the fixed-b critical value of that
estimator (Kiefer & Vogelsang 2005). A parameter is identifiable when its interval is
narrower than its value and it correlates at most :data:`MAX_CORRELATION` with every other
fitted parameter. No interval is given where the data cannot give one: a parameter the
trips do not move, or one that would absorb the cab's and the box's draw of trips measured
without their outside temperature.
"""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from annotated_types import Ge, Gt, Le, Lt
from pydantic import Field
from scipy import optimize

from core.arrays import FloatArray
from core.exceptions import InvalidParameterError
from core.params import (
    CargoBoxParams,
    DoorOpening,
    Location,
    VanParams,
    VehicleParams,
    Weather,
)
from core.params.base import Params, Result
from core.physics.simulate import (
    MAX_ABS_GRADE,
    MAX_PAYLOAD_KG,
    MAX_SPEED_MPS,
    Along,
    SimulationResult,
    simulate,
)

#: Each parameter that can be fitted and the section of the van that holds it.
FITTABLE: dict[str, type[Params]] = {  # the names of FittableName
    "drag_coefficient": VehicleParams,
    "rolling_resistance_coefficient": VehicleParams,
    "drivetrain_efficiency": VehicleParams,
    "regen_efficiency": VehicleParams,
    "auxiliaries_power_w": VehicleParams,
    "wall_heat_transfer_w_m2k": CargoBoxParams,
    "cop": CargoBoxParams,
}
_SECTION = {VehicleParams: "vehicle", CargoBoxParams: "cargo_box"}
#: Fitted when none are named: the drive train and the auxiliaries, and the box when its
#: refrigeration is measured (:data:`BOX_PARAMETERS`).
DEFAULT_PARAMETERS = (
    "drag_coefficient",
    "rolling_resistance_coefficient",
    "drivetrain_efficiency",
    "regen_efficiency",
    "auxiliaries_power_w",
)
BOX_PARAMETERS = ("wall_heat_transfer_w_m2k", "cop")
#: What can be measured: a channel's name and the consumers whose power it is the sum of.
CHANNELS: dict[str, tuple[str, ...]] = {
    "battery_power_w": ("traction", "auxiliaries", "cabin", "refrigeration"),
    "traction_power_w": ("traction",),
    "auxiliaries_power_w": ("auxiliaries",),
    "cabin_power_w": ("cabin",),
    "refrigeration_power_w": ("refrigeration",),
}
#: Two fitted parameters correlated above this cannot be told apart by the data.
MAX_CORRELATION = 0.95
#: The shortest trip that is fitted [s].
MIN_TRIP_S = 60.0
#: Relative step of the finite-difference Jacobian.
DIFF_STEP = 1e-4
#: Folds of the cross-validation when no trip is marked for validation (at most one per trip).
FOLDS = 5
#: Largest power a measured channel may hold [W]: no van draws or regenerates 5 MW.
MAX_MEASURED_POWER_W = 5e6
#: Sparsest sampling a trip may have (its median step) [s]: the simulation's longest step.
MAX_STEP_S = 3600.0


FittableName = Literal[
    "drag_coefficient",
    "rolling_resistance_coefficient",
    "drivetrain_efficiency",
    "regen_efficiency",
    "auxiliaries_power_w",
    "wall_heat_transfer_w_m2k",
    "cop",
]


class FitParameter(Params):
    """A parameter to fit, by its name, within [``min``, ``max``] (the parameter's own bounds
    where absent)."""

    name: FittableName = Field(..., description="The parameter's name, as in the van's models.")
    min: float | None = Field(None, description="Lowest value the fit may give; absent: its own.")
    max: float | None = Field(None, description="Highest value the fit may give; absent: its own.")


@dataclass(frozen=True)
class MeasuredTrip:
    """One trip of the van as its telematics recorded it.

    Attributes
    ----------
    id, role
        The trip's name; ``fit`` or ``validation`` (None: fitted, or cross-validated when no
        trip is marked ``validation``).
    start, location
        When (timezone-aware) and where it began: the sun and the climatology.
    time_s
        Sample times [s], strictly increasing, any step.
    speed_mps
        Speed at each sample [m/s].
    grade, payload_kg, ambient_c
        Road grade [–], payload [kg] and outside temperature [°C] at each sample; None: flat,
        the van's payload, the climatology.
    door_openings
        When the cargo door was open, seconds after the first sample.
    measured_w
        What was measured [W] at each sample, by channel (:data:`CHANNELS`).
    """

    id: str
    start: dt.datetime
    location: Location
    time_s: FloatArray
    speed_mps: FloatArray
    measured_w: Mapping[str, FloatArray]
    role: str | None = None
    grade: FloatArray | None = None
    payload_kg: FloatArray | None = None
    ambient_c: FloatArray | None = None
    door_openings: Sequence[DoorOpening] = ()


class FittedParameter(Result):
    """One fitted parameter: its value, where it started, its standard error, its 95 %
    interval and whether the data tell it apart."""

    name: str = Field(..., description="The parameter, as the request names it.")
    value: float = Field(..., description="The fitted value.")
    initial: float = Field(..., description="The starting van's value.")
    std_error: float | None = Field(
        ...,
        description="Standard error at the solution: a sandwich with the Newey–West covariance "
        "of the residuals (robust to noise that grows with the power and is correlated in "
        "time); null where no interval is given.",
    )
    ci95: tuple[float, float] | None = Field(
        ...,
        description="95 % interval [low, high] (fixed-b critical value, Kiefer & Vogelsang "
        "2005), within the parameter's bounds; null where the data cannot give one: the trips "
        "do not move the parameter, or it would absorb the cab's and box's draw of trips "
        "without ambient_c (a warning says so).",
    )
    identifiable: bool = Field(
        ...,
        description="Whether the data tell it apart: an interval given, narrower than its "
        "value, and no correlation above 0.95 with another fitted parameter.",
    )


#: What a trip was to the fit: fitted to, or predicted (validation).
TripRole = Literal["fit", "validation"]


class TripFit(Result):
    """How the model with the fitted parameters follows one trip."""

    id: str = Field(..., description="The trip.")
    role: TripRole = Field(..., description="fit or validation.")
    r2: float | None = Field(
        ...,
        description="Coefficient of determination of the power [–]; null when the measured "
        "power does not vary.",
    )
    rmse_w: float = Field(..., description="RMS error of the power over its channels [W].")
    energy_error_pct: float | None = Field(
        ...,
        description="Simulated against measured energy [%]; null when no energy was measured.",
    )


@dataclass(frozen=True)
class Calibration:
    """The fit: the parameters, the van with them, each trip's fit, the validation and what
    the data could not tell."""

    parameters: list[FittedParameter]
    van: VanParams
    trips: list[TripFit]
    validation: list[TripFit]
    validation_method: str
    warnings: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class _Resampled:
    """A trip on the simulation's uniform step, with the measured power of each step."""

    trip: MeasuredTrip
    dt_s: float
    speed_mps: FloatArray
    grade: FloatArray | float
    payload_kg: FloatArray | None
    measured_w: dict[str, FloatArray]  # per step: the mean of its two ends


def calibrate(
    van: VanParams, trips: Sequence[MeasuredTrip], parameters: Sequence[FitParameter]
) -> Calibration:
    """Fit ``parameters`` of ``van`` to ``trips`` (bounded least squares, trust region
    reflective), then validate on the trips marked ``validation`` or, with none, by k-fold
    cross-validation over the fitted trips."""
    chosen = _checked(van, parameters or _defaults(trips))
    if not trips:
        raise InvalidParameterError("at least one trip is needed", "trips")
    check_trips(trips)
    resampled = [_resample(trip) for trip in trips]
    fitted = [r for r in resampled if r.trip.role != "validation"]
    held_out = [r for r in resampled if r.trip.role == "validation"]
    if not fitted:
        raise InvalidParameterError("at least one trip must be fitted (role 'fit')", "trips")
    solution = _solve(van, fitted, chosen)
    best = _with(van, chosen, solution.x)
    unmeasured = _unmeasured(chosen, fitted)
    result = _uncertainty(chosen, solution, fitted, unmeasured)
    warnings = (
        result.warnings
        + _warnings(result.correlation, chosen, fitted)
        + _temperature_warnings(fitted, unmeasured)
        + _stretched(best, resampled)
    )
    trips_fit = [_trip_fit(best, r, "fit") for r in fitted]
    if held_out:
        validation = [_trip_fit(best, r, "validation") for r in held_out]
        method = "validation trips"
    else:
        validation, method = _cross_validation(van, fitted, chosen)
    return Calibration(result.parameters, best, trips_fit, validation, method, warnings)


#: What each column may hold: the simulation's own bounds (a grade, a payload, the weather's
#: temperatures) and, for a measured power, what no van draws or regenerates [W].
COLUMN_BOUNDS: dict[str, tuple[float, float]] = {
    "speed_mps": (0.0, MAX_SPEED_MPS),
    "grade": (-MAX_ABS_GRADE, MAX_ABS_GRADE),
    "payload_kg": (0.0, MAX_PAYLOAD_KG),
    "ambient_c": (-60.0, 60.0),
    **{channel: (-MAX_MEASURED_POWER_W, MAX_MEASURED_POWER_W) for channel in CHANNELS},
}


def check_trips(trips: Sequence[MeasuredTrip]) -> None:
    """Every trip usable (:func:`check_trip`) and named once."""
    seen: dict[str, int] = {}
    for k, trip in enumerate(trips):
        if trip.id in seen:
            raise InvalidParameterError(
                f"trip id {trip.id[:60]!r} is used twice (also by trips[{seen[trip.id]}]); ids "
                "must be unique",
                f"trips[{k}].id",
            )
        seen[trip.id] = k
        check_trip(trip, f"trips[{k}]")


def check_trip(trip: MeasuredTrip, where: str) -> None:
    """Refuse a trip the fit cannot use, naming the column and the row (``trips[2].speed_mps[17]``):
    columns of different lengths, a value that is not a finite number or outside what the
    column may hold (:data:`COLUMN_BOUNDS`), times that do not increase, a trip shorter than
    :data:`MIN_TRIP_S` or sampled more sparsely than once an hour, a door opening after its
    end, nothing measured or a channel not in :data:`CHANNELS`."""
    time_s = np.asarray(trip.time_s, dtype=float)
    columns: dict[str, FloatArray | None] = {
        "time_s": time_s,
        "speed_mps": trip.speed_mps,
        "grade": trip.grade,
        "payload_kg": trip.payload_kg,
        "ambient_c": trip.ambient_c,
        **trip.measured_w,
    }
    if not trip.measured_w:
        known = ", ".join(CHANNELS)
        raise InvalidParameterError(f"nothing measured: give one of {known}", where)
    for name, values in columns.items():
        if values is None:
            continue
        field = f"{where}.{name}"
        if name not in CHANNELS and name not in (
            "time_s",
            "speed_mps",
            "grade",
            "payload_kg",
            "ambient_c",
        ):
            raise InvalidParameterError(
                f"'{name}' is not a measured channel: {', '.join(CHANNELS)}", field
            )
        array = np.asarray(values, dtype=float)
        if array.shape != time_s.shape:
            raise InvalidParameterError(
                f"{array.size} values where time_s has {time_s.size}: every column needs one "
                "value per sample",
                field,
            )
        bad = np.flatnonzero(~np.isfinite(array))
        if bad.size:
            raise InvalidParameterError("must be a finite number", f"{field}[{bad[0]}]")
        low, high = COLUMN_BOUNDS.get(name, (-math.inf, math.inf))
        wrong = np.flatnonzero((array < low) | (array > high))
        if wrong.size:
            raise InvalidParameterError(
                f"{array[wrong[0]]:g} is not within {low:g}…{high:g}", f"{field}[{wrong[0]}]"
            )
    steps = np.diff(time_s)
    backwards = np.flatnonzero(steps <= 0)
    if backwards.size:
        row = int(backwards[0]) + 1
        raise InvalidParameterError(
            f"time_s must increase strictly: {time_s[row]:g} s follows {time_s[row - 1]:g} s",
            f"{where}.time_s[{row}]",
        )
    if time_s.size < 2 or time_s[-1] - time_s[0] < MIN_TRIP_S:
        span = float(time_s[-1] - time_s[0]) if time_s.size else 0.0
        raise InvalidParameterError(
            f"a trip must last at least {MIN_TRIP_S:.0f} s; this one lasts {span:g} s",
            f"{where}.time_s",
        )
    if float(np.median(steps)) > MAX_STEP_S:
        raise InvalidParameterError(
            f"the samples are {float(np.median(steps)):g} s apart (the median step); the fit "
            f"needs one at least every {MAX_STEP_S:.0f} s",
            f"{where}.time_s",
        )
    span_s = float(time_s[-1] - time_s[0])
    for k, opening in enumerate(trip.door_openings):
        if opening.start_s > span_s:
            raise InvalidParameterError(
                f"starts {opening.start_s:g} s after the first sample, after the trip ends "
                f"({span_s:g} s)",
                f"{where}.door_openings[{k}].start_s",
            )


def _defaults(trips: Sequence[MeasuredTrip]) -> list[FitParameter]:
    box = any("refrigeration_power_w" in trip.measured_w for trip in trips)
    names = DEFAULT_PARAMETERS + (BOX_PARAMETERS if box else ())
    return [FitParameter(name=name) for name in names]  # type: ignore[arg-type]


def _checked(van: VanParams, parameters: Sequence[FitParameter]) -> list[_Bounded]:
    """Each named parameter with its bounds (the field's, narrowed by the request's)."""
    chosen: list[_Bounded] = []
    for k, parameter in enumerate(parameters):
        where = f"parameters[{k}]"
        if any(c.name == parameter.name for c in chosen):
            raise InvalidParameterError(f"'{parameter.name}' is named twice", f"{where}.name")
        low, high = _field_bounds(FITTABLE[parameter.name], parameter.name)
        low = low if parameter.min is None else max(low, parameter.min)
        high = high if parameter.max is None else min(high, parameter.max)
        initial = _value(van, parameter.name)
        if not low < high:
            raise InvalidParameterError(
                f"min must be below max, and within the parameter's own {low}…{high}",
                f"{where}.min",
            )
        if not low <= initial <= high:
            raise InvalidParameterError(
                f"the starting value {initial:g} of '{parameter.name}' lies outside "
                f"{low:g}…{high:g}",
                f"{where}.min" if initial < low else f"{where}.max",
            )
        chosen.append(_Bounded(parameter.name, low, high, initial))
    return chosen


@dataclass(frozen=True)
class _Bounded:
    name: str
    low: float
    high: float
    initial: float

    @property
    def scale(self) -> float:
        """The unit the solver moves the parameter in: its start, or its range when it
        starts at 0 (a regeneration that is off)."""
        return abs(self.initial) if self.initial else self.high - self.low


def _field_bounds(section: type[Params], name: str) -> tuple[float, float]:
    """The bounds the parameter's own model declares (open bounds nudged inside)."""
    low, high = -math.inf, math.inf
    for rule in section.model_fields[name].metadata:
        if isinstance(rule, Ge):
            low = float(rule.ge)  # type: ignore[arg-type]
        elif isinstance(rule, Gt):
            low = math.nextafter(float(rule.gt), math.inf)  # type: ignore[arg-type]
        elif isinstance(rule, Le):
            high = float(rule.le)  # type: ignore[arg-type]
        elif isinstance(rule, Lt):
            high = math.nextafter(float(rule.lt), -math.inf)  # type: ignore[arg-type]
    return low, high


def _value(van: VanParams, name: str) -> float:
    section = getattr(van, _SECTION[FITTABLE[name]])
    return float(getattr(section, name))


def _with(van: VanParams, chosen: Sequence[_Bounded], x: FloatArray) -> VanParams:
    """``van`` with each chosen parameter at ``x`` (in units of its scale)."""
    changes: dict[str, dict[str, float]] = {}
    for parameter, value in zip(chosen, x, strict=True):
        section = _SECTION[FITTABLE[parameter.name]]
        bounded = min(max(float(value) * parameter.scale, parameter.low), parameter.high)
        changes.setdefault(section, {})[parameter.name] = bounded
    update = {
        section: getattr(van, section).model_copy(update=values)
        for section, values in changes.items()
    }
    return van.model_copy(update=update)


def _resample(trip: MeasuredTrip) -> _Resampled:
    """The trip on a uniform step (its median step). A measured sample is the mean power since
    the sample before (what a differentiated energy counter gives): each step's mean comes
    from the measured energy, summed and interpolated at the step's ends."""
    time_s = np.asarray(trip.time_s, dtype=float)
    step_s = float(np.median(np.diff(time_s)))
    n = math.floor((time_s[-1] - time_s[0]) / step_s + 1e-9) + 1
    grid_s = time_s[0] + step_s * np.arange(n)

    def at_grid(values: FloatArray) -> FloatArray:
        return np.interp(grid_s, time_s, np.asarray(values, dtype=float))

    measured: dict[str, FloatArray] = {}
    for channel, values in trip.measured_w.items():
        energy_j = np.concatenate([[0.0], np.cumsum(np.asarray(values)[1:] * np.diff(time_s))])
        measured[channel] = np.diff(at_grid(energy_j)) / step_s
    return _Resampled(
        trip,
        step_s,
        np.maximum(at_grid(trip.speed_mps), 0.0),
        0.0 if trip.grade is None else at_grid(trip.grade),
        None if trip.payload_kg is None else at_grid(trip.payload_kg),
        measured,
    )


def _simulated(van: VanParams, trip: _Resampled) -> SimulationResult:
    return simulate(
        trip.speed_mps,
        trip.dt_s,
        trip.trip.start,
        trip.trip.location,
        van,
        weather=_weather(trip),
        along=Along(
            grade=trip.grade, payload_kg=trip.payload_kg, door_openings=trip.trip.door_openings
        ),
    )


def _weather(trip: _Resampled) -> Weather | None:
    """The trip's measured outside temperature as the day's extremes, or the climatology."""
    if trip.trip.ambient_c is None:
        return None
    low, high = float(np.min(trip.trip.ambient_c)), float(np.max(trip.trip.ambient_c))
    return Weather(t_min_c=low, t_max_c=max(high, low))


def _channel_w(result: SimulationResult, channel: str, steps: int) -> FloatArray:
    """The channel's simulated power over the trip's ``steps``: where the van's motor cap made
    the simulation drive the trace slower than measured, its first ``steps`` (a warning says
    so, :func:`_stretched`)."""
    power = np.sum([result.power_w[c] for c in CHANNELS[channel]], axis=0)
    if power.size < steps:
        return np.concatenate([power, np.full(steps - power.size, power[-1])])
    return power[:steps]


def _stretched(van: VanParams, trips: Sequence[_Resampled]) -> list[str]:
    """A warning for each trip the fitted van's motor could not follow as measured."""
    warnings = []
    for trip in trips:
        for warning in _simulated(van, trip).warnings:
            warnings.append(f"trip '{trip.trip.id}': {warning}; fitted on the trace as measured")
    return warnings


def _residuals(
    van: VanParams, trips: Sequence[_Resampled], weights: Mapping[str, float]
) -> FloatArray:
    """Every step's simulated minus measured power, per channel, over its weight."""
    parts = []
    for trip in trips:
        result = _simulated(van, trip)
        for channel, measured in trip.measured_w.items():
            simulated = _channel_w(result, channel, measured.size)
            parts.append((simulated - measured) / weights[channel])
    return np.concatenate(parts)


def _weights(trips: Sequence[_Resampled]) -> dict[str, float]:
    """Each channel's spread [W] over the fitted trips (1 W at least)."""
    channels = {c for t in trips for c in t.measured_w}
    spread = {
        c: float(np.std(np.concatenate([t.measured_w[c] for t in trips if c in t.measured_w])))
        for c in channels
    }
    return {c: max(value, 1.0) for c, value in spread.items()}


def _solve(
    van: VanParams, trips: Sequence[_Resampled], chosen: Sequence[_Bounded]
) -> optimize.OptimizeResult:
    weights = _weights(trips)
    x0 = np.array([p.initial / p.scale for p in chosen])
    low = np.array([p.low / p.scale for p in chosen])
    high = np.array([p.high / p.scale for p in chosen])

    def residuals(x: FloatArray) -> FloatArray:
        return _residuals(_with(van, chosen, x), trips, weights)

    return optimize.least_squares(
        residuals, x0, bounds=(low, high), method="trf", diff_step=DIFF_STEP, x_scale=1.0
    )


@dataclass(frozen=True)
class _Uncertainty:
    parameters: list[FittedParameter]
    correlation: FloatArray
    warnings: list[str] = field(default_factory=list)


#: The HAC estimator's bandwidth as a share of each measured series (fixed-b, Kiefer &
#: Vogelsang 2005): with its critical value (:func:`fixed_b_quantile`) the intervals keep
#: their coverage whether the noise is independent or strongly correlated in time.
HAC_BANDWIDTH_SHARE = 0.15


def fixed_b_quantile(b: float) -> float:
    """The 97.5 % quantile of the t-statistic with a Bartlett HAC variance of bandwidth share
    ``b`` (Kiefer, N. M. & Vogelsang, T. J., "A new asymptotic theory for
    heteroskedasticity-autocorrelation robust tests", *Econometric Theory* 21 (2005)
    1130–1164, their cubic fit of the two-sided 5 % critical values); 1.96 at ``b = 0``."""
    return 1.96 + 2.9694 * b + 0.4160 * b**2 - 0.5324 * b**3


def hac_scores(scores: FloatArray, series: Sequence[tuple[int, int]]) -> FloatArray:
    """The long-run covariance of the residuals' scores ``g_t = J_t·r_t`` (m × p) [–]:
    Newey–West (Bartlett weights ``1 − l/(L+1)``) within each measured series (a trip's
    channel, rows ``a:b``), the series independent of each other, the bandwidth ``L`` a share
    :data:`HAC_BANDWIDTH_SHARE` of each series. Newey, W. K. & West, K. D., *Econometrica* 55
    (1987) 703–708: robust to noise that grows with the power and is correlated in time."""
    p = scores.shape[1]
    covariance = np.zeros((p, p))
    for a, b in series:
        g = scores[a:b]
        covariance += g.T @ g
        lags = min(math.ceil(HAC_BANDWIDTH_SHARE * (b - a)), b - a - 1)
        for lag in range(1, lags + 1):
            shifted = g[lag:].T @ g[:-lag]
            covariance += (1 - lag / (lags + 1)) * (shifted + shifted.T)
    return covariance


def _series(trips: Sequence[_Resampled]) -> list[tuple[int, int]]:
    """Where each trip's channel lies in the stacked residuals (:func:`_residuals`)."""
    bounds, at = [], 0
    for trip in trips:
        for measured in trip.measured_w.values():
            bounds.append((at, at + measured.size))
            at += measured.size
    return bounds


def _uncertainty(
    chosen: Sequence[_Bounded],
    solution: optimize.OptimizeResult,
    trips: Sequence[_Resampled],
    unmeasured: set[str],
) -> _Uncertainty:
    """The sandwich covariance at the solution, ``(JᵀJ)⁻¹·S·(JᵀJ)⁻¹`` with ``S`` the HAC
    covariance of the scores (:func:`hac_scores`), and the fixed-b quantile for the 95 %
    intervals. No interval where the data cannot give one: a parameter the Jacobian does not
    see, or one in ``unmeasured`` (it would absorb what the trips did not measure)."""
    jac = np.asarray(solution.jac, dtype=float)
    m, p = jac.shape
    bread = np.linalg.pinv(jac.T @ jac)
    scores = jac * np.asarray(solution.fun, dtype=float)[:, None]
    covariance = bread @ hac_scores(scores, _series(trips)) @ bread * m / max(m - p, 1)
    std = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    # Whether the data tell two parameters apart is the design's (the Jacobian's columns),
    # not the noise's: the correlation of (JᵀJ)⁻¹.
    spread = np.sqrt(np.maximum(np.diag(bread), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = bread / np.outer(spread, spread)
    correlation = np.nan_to_num(correlation, nan=1.0)
    quantile = fixed_b_quantile(HAC_BANDWIDTH_SHARE)
    seen = np.abs(jac).sum(axis=0) > 0
    # among the parameters the trips see (one they do not leaves the others their intervals)
    singular = np.linalg.matrix_rank(jac[:, seen]) < int(seen.sum())
    fitted, warnings = [], []
    for k, parameter in enumerate(chosen):
        value = float(solution.x[k]) * parameter.scale
        error = float(std[k]) * parameter.scale
        apart = all(abs(correlation[k, j]) <= MAX_CORRELATION for j in range(p) if j != k)
        given = bool(seen[k]) and not singular and parameter.name not in unmeasured
        identifiable = given and apart and error * quantile < abs(value)
        interval = (
            (
                max(value - quantile * error, parameter.low),
                min(value + quantile * error, parameter.high),
            )
            if given
            else None
        )
        fitted.append(
            FittedParameter(
                name=parameter.name,
                value=value,
                initial=parameter.initial,
                std_error=error if given else None,
                ci95=interval,
                identifiable=identifiable,
            )
        )
        if not seen[k]:  # why no interval, said (unmeasured ones have their own warning)
            warnings.append(
                f"'{parameter.name}' changes nothing the trips measured (no measured power "
                "includes what it drives: the refrigeration's for cop, say): it stays at "
                f"{value:g}, no interval given; measure that power to fit it"
            )
        elif singular and parameter.name not in unmeasured:
            warnings.append(
                f"'{parameter.name}': the trips cannot fix every chosen parameter at once (the "
                "fit's Jacobian is singular): no interval given; fit fewer parameters"
            )
    return _Uncertainty(fitted, correlation, warnings)


#: The consumers whose draw follows the outside temperature (the cab's HVAC, the box's
#: unit), and the parameters that would absorb an error in it: a constant draw, the box.
TEMPERATURE_CONSUMERS = ("cabin", "refrigeration")
ABSORB_TEMPERATURE = ("auxiliaries_power_w", "wall_heat_transfer_w_m2k", "cop")


def _unmeasured(chosen: Sequence[_Bounded], trips: Sequence[_Resampled]) -> set[str]:
    """The parameters no interval is given for: those that absorb the cab's and the box's
    draw when a trip whose measured power includes them has no outside temperature (the
    climatology stands in, and its error goes into them)."""
    blind = [
        t
        for t in trips
        if t.trip.ambient_c is None
        and any(set(CHANNELS[c]) & set(TEMPERATURE_CONSUMERS) for c in t.measured_w)
    ]
    return {p.name for p in chosen if p.name in ABSORB_TEMPERATURE} if blind else set()


def _temperature_warnings(trips: Sequence[_Resampled], unmeasured: set[str]) -> list[str]:
    """What the fit could not tell for want of the outside temperature."""
    if not unmeasured:
        return []
    blind = [t.trip.id for t in trips if t.trip.ambient_c is None]
    names = ", ".join(sorted(unmeasured))
    return [
        f"trip{'s' * (len(blind) > 1)} {', '.join(repr(i) for i in blind[:5])} "
        f"{'have' if len(blind) > 1 else 'has'} no ambient_c: the cab's and the box's draw come "
        f"from the climatology, and its error goes into {names} — not identifiable from these "
        "trips, no interval given; the other intervals assume the climatology's temperatures "
        "(measure ambient_c)"
    ]


def _warnings(
    correlation: FloatArray, chosen: Sequence[_Bounded], trips: Sequence[_Resampled]
) -> list[str]:
    """What the data could not tell apart."""
    warnings = []
    names = [p.name for p in chosen]
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            if abs(correlation[a, b]) > MAX_CORRELATION:
                warnings.append(
                    f"'{names[a]}' and '{names[b]}' are correlated at {correlation[a, b]:+.2f}: "
                    "the data cannot tell them apart"
                )
    if {"drag_coefficient", "rolling_resistance_coefficient"} <= set(names):
        speeds = np.concatenate([t.speed_mps[t.speed_mps > 1.0] for t in trips] or [np.zeros(1)])
        spread = float(np.ptp(speeds)) if speeds.size else 0.0
        if spread < SEPARATING_SPEEDS_MPS:
            warnings.append(
                "no trip is fast enough to separate drag from rolling resistance: the speeds "
                f"driven span {spread:.1f} m/s, and telling them apart takes trips both slow "
                f"and fast (a span of {SEPARATING_SPEEDS_MPS:.0f} m/s or more)"
            )
    return warnings


#: The span of driven speeds that separates drag (∝ v²) from rolling resistance [m/s].
SEPARATING_SPEEDS_MPS = 10.0


def _trip_fit(van: VanParams, trip: _Resampled, role: TripRole) -> TripFit:
    result = _simulated(van, trip)
    simulated = np.concatenate([_channel_w(result, c, m.size) for c, m in trip.measured_w.items()])
    measured = np.concatenate(list(trip.measured_w.values()))
    error = simulated - measured
    spread = float(np.sum((measured - measured.mean()) ** 2))
    r2 = 1.0 - float(np.sum(error**2)) / spread if spread > 0 else None
    measured_j = float(np.sum(measured)) * trip.dt_s
    simulated_j = float(np.sum(simulated)) * trip.dt_s
    # No energy measured (a channel of zeros): no relative error to give.
    energy_error = (simulated_j - measured_j) / abs(measured_j) * 100 if measured_j else None
    return TripFit(
        id=trip.trip.id,
        role=role,
        r2=r2,
        rmse_w=float(np.sqrt(np.mean(error**2))),
        energy_error_pct=energy_error,
    )


def _cross_validation(
    van: VanParams, trips: Sequence[_Resampled], chosen: Sequence[_Bounded]
) -> tuple[list[TripFit], str]:
    """Each fold of the trips predicted by a fit to the others (k-fold, at most
    :data:`FOLDS`); none with a single trip."""
    folds = min(FOLDS, len(trips))
    if folds < 2:
        return [], "none (a single trip)"
    predicted = []
    for fold in range(folds):
        rest = [t for k, t in enumerate(trips) if k % folds != fold]
        solution = _solve(van, rest, chosen)
        fold_van = _with(van, chosen, solution.x)
        predicted += [
            _trip_fit(fold_van, t, "validation") for k, t in enumerate(trips) if k % folds == fold
        ]
    return predicted, f"{folds}-fold cross-validation"
