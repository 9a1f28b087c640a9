"""Parameter models: one definition of every parameter, with its unit, bounds and default.

The models are frozen pydantic models so that the web layer reuses them directly: Swagger shows
exactly what Python users see. Defaults are the paper's Table 1 where it gives a value; every
other default is ours and its field description says where it comes from. The submodules hold
the base and the text types (:mod:`~core.params.base`), the van (:mod:`~core.params.van`), the
conditions (:mod:`~core.params.conditions`), the places (:mod:`~core.params.places`) and the
presets (:mod:`~core.params.presets`); everything is importable from here.
"""

from core.params.base import (
    GRAVITY_MPS2,
    HHMM_PATTERN,
    MAX_TRACE_SAMPLES,
    MAX_UNKNOWN_NAMED,
    NEDC_DURATION_S,
    ClockTime,
    IsoDate,
    IsoDateTime,
    Params,
    clock_field,
    clock_time,
    describe_validation_error,
    few_unknown,
    inside_validation,
)
from core.params.conditions import (
    AGGRESSIVE_DRIVER,
    CALM_DRIVER,
    LEAST_RAMP_SHARE,
    MAX_INTERVALS,
    MAX_TRAFFIC_DENSITY,
    MIN_TRAFFIC_DENSITY,
    NORMAL_DRIVER,
    STREET_TYPES,
    ChargingSpell,
    DoorOpening,
    Interval,
    Location,
    StreetType,
    StreetTypeName,
    TrafficDensity,
    Weather,
)
from core.params.places import (
    MAX_MATRIX_DISTANCE_M,
    MAX_MATRIX_DURATION_S,
    MAX_STOPS,
    MAX_TIME_WINDOWS,
    Depot,
    Objective,
    RoadMatrix,
    Stop,
    TimeWindow,
)
from core.params.presets import DEFAULT_PRESET, PRESETS, Preset, get_preset
from core.params.van import (
    MIN_SOC_WINDOW,
    BatteryParams,
    CargoBoxParams,
    VanParams,
    VehicleParams,
)

__all__ = [
    "AGGRESSIVE_DRIVER",
    "CALM_DRIVER",
    "DEFAULT_PRESET",
    "GRAVITY_MPS2",
    "HHMM_PATTERN",
    "LEAST_RAMP_SHARE",
    "MAX_INTERVALS",
    "MAX_MATRIX_DISTANCE_M",
    "MAX_MATRIX_DURATION_S",
    "MAX_STOPS",
    "MAX_TIME_WINDOWS",
    "MAX_TRACE_SAMPLES",
    "MAX_TRAFFIC_DENSITY",
    "MAX_UNKNOWN_NAMED",
    "MIN_SOC_WINDOW",
    "MIN_TRAFFIC_DENSITY",
    "NEDC_DURATION_S",
    "NORMAL_DRIVER",
    "PRESETS",
    "STREET_TYPES",
    "BatteryParams",
    "CargoBoxParams",
    "ChargingSpell",
    "ClockTime",
    "Depot",
    "DoorOpening",
    "Interval",
    "IsoDate",
    "IsoDateTime",
    "Location",
    "Objective",
    "Params",
    "Preset",
    "RoadMatrix",
    "Stop",
    "StreetType",
    "StreetTypeName",
    "TimeWindow",
    "TrafficDensity",
    "VanParams",
    "VehicleParams",
    "Weather",
    "clock_field",
    "clock_time",
    "describe_validation_error",
    "few_unknown",
    "get_preset",
    "inside_validation",
]
