import math

import numpy as np
import pytest

from core.exceptions import InvalidMatrixError
from core.params import STREET_TYPES, Depot, RoadMatrix
from core.routing.geo import (
    DETOUR_FACTOR,
    EARTH_RADIUS_M,
    build_legs,
    great_circle_m,
    street_type_by_length,
    street_type_by_speed,
)


def test_one_degree_of_latitude():
    # π/180 · 6,371,008.8 m = 111,195.08 m
    d = great_circle_m(np.array([0.0, 1.0]), np.array([10.0, 10.0]))
    assert d[0, 1] == pytest.approx(math.pi / 180 * EARTH_RADIUS_M, rel=1e-12)
    assert d[1, 0] == d[0, 1] and d[0, 0] == 0


def test_vienna_to_salzburg():
    # Stephansplatz (48.2085, 16.3731) – Salzburg Dom (47.7981, 13.0466): 251.2 km great circle
    d = great_circle_m(np.array([48.2085, 47.7981]), np.array([16.3731, 13.0466]))
    assert d[0, 1] == pytest.approx(251_200, rel=0.002)


def test_street_type_rule():
    assert list(street_type_by_length(np.array([100, 5000, 5001, 25_000, 25_001]))) == [
        0,
        0,
        1,
        1,
        2,
    ]


def test_default_legs_distance_duration_grade():
    places = [
        Depot(lat=48.20, lon=16.37, elevation_m=170),
        Depot(lat=48.21, lon=16.37, elevation_m=200),
    ]
    legs = build_legs(places)
    crow = math.pi / 180 * 0.01 * EARTH_RADIUS_M
    assert legs.distance_m[0, 1] == pytest.approx(crow * DETOUR_FACTOR)
    assert legs.duration_s[0, 1] == pytest.approx(
        legs.distance_m[0, 1] / STREET_TYPES["urban"].mean_speed_mps
    )
    assert legs.grade[0, 1] == pytest.approx(30 / legs.distance_m[0, 1])
    assert legs.grade[1, 0] == pytest.approx(-legs.grade[0, 1])
    assert legs.street_type_name(0, 1) == "urban" and legs.source == "estimate"


def test_missing_elevation_means_flat():
    legs = build_legs([Depot(lat=48.2, lon=16.37, elevation_m=170), Depot(lat=48.21, lon=16.37)])
    assert legs.grade[0, 1] == 0


MATRIX = {"distances_m": [[0, 1000], [1200, 0]], "durations_s": [[0, 120], [150, 0]]}
TWO = [Depot(lat=48.2, lon=16.37), Depot(lat=48.21, lon=16.37)]


def test_client_matrix_is_used_as_is():
    legs = build_legs(
        TWO, RoadMatrix(**MATRIX, street_types=[["urban", "highway"], ["highway", "urban"]])
    )
    assert legs.distance_m[1, 0] == 1200 and legs.duration_s[0, 1] == 120
    assert legs.street_type_name(0, 1) == "highway" and legs.source == "client"


def test_client_matrix_without_street_types_types_legs_by_speed():
    # 1000 m in 120 s = 30 km/h: urban; 20 km in 15 min = 80 km/h: expressway (≥ 80 km/h)
    matrix = RoadMatrix(distances_m=[[0, 1000], [20_000, 0]], durations_s=[[0, 120], [900, 0]])
    legs = build_legs(TWO, matrix)
    assert legs.street_type_name(0, 1) == "urban"
    assert legs.street_type_name(1, 0) == "expressway"


def test_street_type_by_speed_bounds():
    # 45 and 80 km/h, between the street types' 30, 70 and 100 km/h
    distance = np.array([44.9, 45.0, 79.9, 80.0, 10.0]) / 3.6 * 3600
    duration = np.array([3600.0, 3600, 3600, 3600, 0])
    assert list(street_type_by_speed(distance, duration)) == [0, 1, 1, 2, 0]


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"distances_m": [[0, 1000]]}, "matrix.distances_m"),
        ({"distances_m": [[0, 1000], [1200]]}, "matrix.distances_m[1]"),
        ({"distances_m": [[0, -1], [1200, 0]]}, "matrix.distances_m[0][1]"),
        ({"durations_s": [[0, 120], [float("inf"), 0]]}, "matrix.durations_s[1][0]"),
        ({"durations_s": [[5, 120], [150, 0]]}, "matrix.durations_s[0][0]"),
        ({"durations_s": [[0, 0], [150, 0]]}, "matrix.durations_s[0][1]"),
    ],
)
def test_bad_matrix_names_row_and_column(change, field):
    matrix = RoadMatrix.model_construct(**(MATRIX | change), street_types=None)
    with pytest.raises(InvalidMatrixError) as caught:
        build_legs(TWO, matrix)
    assert caught.value.field == field
