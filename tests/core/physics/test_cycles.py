import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from core.exceptions import InvalidParameterError
from core.params import STREET_TYPES, StreetType
from core.physics.cycles import (
    RAMP_TOLERANCE,
    drive_profile,
    fastest_s,
    generate_leg,
    load_cycle_csv,
    nedc,
    rest_to_rest,
    stretch_to_duration,
    trace_distance_m,
)
from core.physics.simulate import MAX_SPEED_MPS

URBAN = STREET_TYPES["urban"]


@given(
    distance=st.floats(1.0, 60_000.0),
    street=st.sampled_from(sorted(STREET_TYPES)),
    aggressiveness=st.floats(0.0, 1.0),
    density=st.one_of(st.none(), st.floats(0.05, 0.95)),
)
@settings(max_examples=60, deadline=None)
def test_leg_from_rest_to_rest_covers_distance(distance, street, aggressiveness, density):
    trace = generate_leg(distance, STREET_TYPES[street], aggressiveness, 2.0, density)
    assert trace[0] == 0 and trace[-1] == 0
    assert np.all(np.isfinite(trace)) and trace.min() >= 0
    assert trace_distance_m(trace, 1.0) == pytest.approx(distance, rel=0.01)


def test_long_leg_keeps_the_mean_speed_and_the_waves():
    # The trapezoid keeps v̄ as its mean (paper §2.2); ramps at the ends lower the leg mean a bit.
    trace = generate_leg(30_000, URBAN, 0.5, 2.0)
    mean_kmh = 30_000 / (trace.size - 1) * 3.6
    assert mean_kmh == pytest.approx(30, rel=0.03)
    assert trace.max() == pytest.approx(URBAN.mean_speed_mps * 1.8, rel=0.01)  # v2 = v̄(1+dv)


def test_aggressive_driver_accelerates_harder():
    calm = np.diff(generate_leg(3000, URBAN, 0.2, 2.0)).max()
    aggressive = np.diff(generate_leg(3000, URBAN, 1.0, 2.0)).max()
    assert calm == pytest.approx(0.4, rel=0.05) and aggressive == pytest.approx(2.0, rel=0.05)


def test_dense_traffic_means_more_waves():
    # t_0 = t_p (1 − ε_t)/ε_t: less cruising between waves at higher density
    light = generate_leg(10_000, URBAN, 0.5, 2.0, traffic_density=0.2)
    dense = generate_leg(10_000, URBAN, 0.5, 2.0, traffic_density=0.9)
    assert np.abs(np.diff(dense)).sum() > 2 * np.abs(np.diff(light)).sum()


def test_generator_is_deterministic_and_zero_leg_is_a_single_sample():
    first = generate_leg(4321, STREET_TYPES["highway"], 0.7, 2.0)
    assert np.array_equal(first, generate_leg(4321, STREET_TYPES["highway"], 0.7, 2.0))
    assert list(generate_leg(0.0, URBAN, 0.5, 2.0)) == [0.0]


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"distance_m": -5}, "distance_m"),
        ({"distance_m": float("nan")}, "distance_m"),
        ({"driver_aggressiveness": 1.5}, "driver_aggressiveness"),
        ({"traffic_density": 1.0}, "traffic_density"),
        ({"dt_s": 0.0}, "dt_s"),
    ],
)
def test_leg_rejects_bad_inputs(kwargs, field):
    args = {
        "distance_m": 1000.0,
        "street": URBAN,
        "driver_aggressiveness": 0.5,
        "max_acceleration_mps2": 2.0,
    } | kwargs
    with pytest.raises(InvalidParameterError) as caught:
        generate_leg(**args)
    assert caught.value.field == field


def test_stretch_keeps_distance_and_hits_duration():
    trace = generate_leg(2000, URBAN, 0.5, 2.0)
    stretched = stretch_to_duration(trace, 1.0, 600.0)
    assert stretched.size - 1 == 600
    assert trace_distance_m(stretched, 1.0) == pytest.approx(2000)
    assert stretched[0] == 0 and stretched[-1] == 0


def test_nedc_from_its_definition():
    # UNECE R83: 1180 s; 4 × ECE-15 (0.994 km each) + EUDC (6.955 km) ≈ 11.02 km, max 120 km/h
    cycle = nedc()
    assert cycle.duration_s == 1180
    assert cycle.distance_m == pytest.approx(11_023, rel=0.005)
    assert cycle.speed_mps.max() * 3.6 == pytest.approx(120)


@pytest.mark.parametrize(
    ("name", "rows", "distance_km"),
    # shared/reference/cycles/SOURCES.md: rows and trapezoid distances
    [
        ("udds", 1370, 11.990),
        ("hwfet", 766, 16.507),
        ("us06", 601, 12.888),
        ("wltc_3b", 1801, 23.266),
    ],
)
def test_loads_both_fastsim_header_styles(reference_dir, name, rows, distance_km):
    cycle = load_cycle_csv(reference_dir / "cycles" / f"{name}.csv")
    assert cycle.speed_mps.size == rows and cycle.dt_s == 1.0
    assert cycle.distance_m / 1000 == pytest.approx(distance_km, abs=0.0005)


def test_loads_own_header_with_grade(tmp_path):
    path = tmp_path / "hill.csv"
    path.write_text("time_s,speed_mps,grade\n0,0,0.02\n2,4,0.02\n4,0,0.02\n")
    cycle = load_cycle_csv(path)
    assert (
        cycle.dt_s == 2.0 and list(cycle.grade) == [0.02] * 3 and cycle.distance_m == 8
    )  # (0+4)/2·2 + (4+0)/2·2


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("", "no data rows"),
        ("t,v\n0,1\n", "unknown header"),
        ("time_s,speed_mps\n0,0\n1,x\n", "non-numeric"),
        ("time_s,speed_mps\n0,0\n1,-3\n", "speed must be finite and >= 0"),
        ("time_s,speed_mps\n0,0\n1,2\n3,0\n", "time steps must be equal"),
        ("time_s,speed_mps\n1,0\n0,0\n", "time must rise"),
    ],
)
def test_bad_csv_is_rejected(tmp_path, content, message):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(InvalidParameterError, match=message):
        load_cycle_csv(path)


STEADY = StreetType(mean_speed_mps=10, speed_variation=0, period_divisor=1, traffic_density=0.5)


def test_road_profile_by_hand():
    # One 1000 m segment at 10 m/s, no waves, calm driver: 0.2 · 2 = 0.4 m/s² up and down.
    # Ramp 25 s and 125 m each way, cruise 750 m in 75 s: 125 s in all.
    trace, travelled = drive_profile(np.array([1000.0]), np.array([10.0]), STEADY, 0.2, 2.0)
    assert trace[0] == trace[-1] == 0
    assert trace.size - 1 == pytest.approx(125, abs=1)
    assert trace.max() == pytest.approx(10.0, rel=1e-3)
    assert trace_distance_m(trace, 1.0) == pytest.approx(1000.0, rel=1e-9)
    assert travelled[-1] == pytest.approx(1000.0) and np.all(np.diff(travelled) >= 0)
    assert np.abs(np.diff(trace)).max() <= 0.4 * 1.01


def test_road_profile_brakes_ahead_of_a_slow_segment():
    # 400 m at 15 m/s, 50 m at 5 m/s (a tight bend), 400 m at 15 m/s
    lengths = np.array([400.0, 50.0, 400.0])
    trace, travelled = drive_profile(lengths, np.array([15.0, 5.0, 15.0]), STEADY, 0.5, 2.0)
    in_bend = (travelled >= 400) & (travelled <= 450)
    assert trace[in_bend].max() <= 5.0 * 1.01
    assert trace.max() == pytest.approx(15.0, rel=0.02)
    assert trace_distance_m(trace, 1.0) == pytest.approx(850.0, rel=1e-9)


def test_road_profile_never_exceeds_the_road_and_traffic_slows_it():
    rng = np.random.default_rng(5)
    lengths = rng.uniform(20, 400, 40)
    speeds = rng.uniform(6, 20, 40)
    light, heavy = (
        drive_profile(lengths, speeds, STREET_TYPES["urban"], 0.5, 2.0, density)[0]
        for density in (0.1, 0.9)
    )
    ceiling = speeds.max()
    assert light.max() <= ceiling * 1.01 and heavy.max() <= ceiling * 1.01
    # more traffic: more slow-downs, a longer leg over the same road
    assert heavy.size > light.size
    free_flow_s = float(np.sum(lengths / speeds))
    assert light.size > free_flow_s  # ramps and slow-downs on top of the free flow


def test_road_profile_rejects_bad_segments():
    with pytest.raises(InvalidParameterError):
        drive_profile(np.array([100.0, -1]), np.array([10.0, 10]), STEADY, 0.5, 2.0)
    with pytest.raises(InvalidParameterError):
        drive_profile(np.array([100.0]), np.array([10.0, 10]), STEADY, 0.5, 2.0)
    # a router's zero or absurd speed is clamped, not trusted
    trace, _ = drive_profile(np.array([100.0, 100]), np.array([0.0, 1e6]), STEADY, 0.5, 2.0)
    assert trace.max() <= 60.0 and trace_distance_m(trace, 1.0) == pytest.approx(200.0)


def test_a_hop_shorter_than_one_sample_still_moves():
    trace, travelled = drive_profile(np.array([0.4]), np.array([12.0]), STEADY, 0.5, 2.0)
    assert trace[0] == trace[-1] == 0 and trace.size >= 3
    assert trace_distance_m(trace, 1.0) == pytest.approx(0.4)
    assert travelled[-1] == pytest.approx(0.4)


@settings(max_examples=300, deadline=None)
@given(
    distance=st.floats(0.1, 200_000),
    duration=st.floats(0, 20_000),
    accel=st.floats(0.2, 10),
)
def test_rest_to_rest_keeps_the_distance_within_the_vans_limits(distance, duration, accel):
    """A leg a client's matrix gives too little time (10 m in 1 s, 100 km in 1000 s) is driven
    over its whole distance, from rest to rest, never faster than 250 km/h and no steeper
    than the van's acceleration (the audits found 10 m driven as 20.5 m, and a 100 km leg
    scaled to 250.000…1 km/h, refused as a speed the client never sent)."""
    top = MAX_SPEED_MPS
    trace = rest_to_rest(distance, duration, accel, top)
    assert trace[0] == 0 and trace[-1] == 0 and trace.size >= 3
    assert trace_distance_m(trace, 1.0) == pytest.approx(distance, rel=1e-9)
    assert trace.max() <= top
    assert np.abs(np.diff(trace)).max() <= accel * (1 + RAMP_TOLERANCE)
    # no longer than the time asked for, or the least the van needs, by more than a step or two
    least = fastest_s(distance, accel, top)
    assert trace.size - 1 <= max(duration, least) * (1 + RAMP_TOLERANCE) + 2


@pytest.mark.parametrize("distance", [5e-324, 1e-310, 1e-9, 1e-7])
def test_a_leg_shorter_than_a_micrometre_stands_still(distance):
    trace = rest_to_rest(distance, 60.0, 1.0, 30.0)
    assert trace.size == 61 and not trace.any()


@pytest.mark.parametrize("distance", [1e-6, 1e-3, 1.0])
def test_a_short_leg_over_a_long_time_covers_its_distance(distance):
    # the cruise speed from 2·a·d / (a·T + √(a²T² − 4·a·d)): no cancellation at a²T² ≫ 4·a·d
    trace = rest_to_rest(distance, 3600.0, 2.0, 30.0)
    assert trace_distance_m(trace, 1.0) == pytest.approx(distance, rel=1e-9)
