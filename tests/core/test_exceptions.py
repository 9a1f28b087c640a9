"""Errors re-scoped under a prefix keep every entry; renamed ones name the new field."""

from __future__ import annotations

import pickle

from core.exceptions import (
    CoreError,
    InvalidParameterError,
    LimitExceededError,
    OffRoadError,
    off_road,
)


def test_under_a_prefix_every_entry_is_kept():
    error = InvalidParameterError(
        "two rules",
        "cargo_box.product_limit_c",
        [("cargo_box.product_limit_c", "above the set-point"), ("battery.min_soc", "below")],
    )
    scoped = error.under("request")
    assert type(scoped) is InvalidParameterError
    assert scoped.field == "request.cargo_box.product_limit_c"
    assert scoped.details == [
        ("request.cargo_box.product_limit_c", "above the set-point"),
        ("request.battery.min_soc", "below"),
    ]
    assert scoped.message == "two rules"


def test_indexes_and_the_whole_body_under_a_prefix():
    assert LimitExceededError("too many", "stops").under("vehicles[2]").field == "vehicles[2].stops"
    assert CoreError("bad", "[3].lat").under("stops").field == "stops[3].lat"
    whole = CoreError("bad body")
    assert whole.under("request").field == "request"
    assert whole.under("request").details == [("request", "bad body")]


def test_at_names_another_field():
    renamed = InvalidParameterError("skipped by daylight saving", "start_time").at(
        "vehicles[0].shift_start"
    )
    assert renamed.field == "vehicles[0].shift_start"
    assert renamed.details == [("vehicles[0].shift_start", "skipped by daylight saving")]


def test_errors_cross_processes_with_their_fields():
    error = InvalidParameterError("x", "a", [("a", "x"), ("b", "y")]).under("request")
    again = pickle.loads(pickle.dumps(error))
    assert (type(again), again.field, again.details) == (
        InvalidParameterError,
        error.field,
        error.details,
    )


def test_an_off_road_place_crosses_processes_with_its_index():
    error = off_road("'x' is 900 m from the nearest road", 3)
    again = pickle.loads(pickle.dumps(error))
    assert (type(again), again.field, again.place) == (OffRoadError, "stops[2]", 3)
    assert off_road("the depot", 0).field == "depot"
