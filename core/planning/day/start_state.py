"""The rest of a day planned again from where the van is (``start_state``): it leaves from its
position, at its time, with its charge, box temperature and payload, serves the stops left and
returns to the depot.

The van's position is one more place after the stops (:func:`core.planning.day.scene.round_places`);
the order is the shortest path from it through every stop to the depot (:func:`path_tour`).
"""

from __future__ import annotations

import datetime as dt

import numpy as np
from numpy.typing import NDArray

from core.exceptions import InvalidParameterError
from core.params import MIN_SOC_WINDOW
from core.planning.model import START_ID, PlanProblem, RoundFields
from core.routing.effort import Effort
from core.routing.tsp import Tour, solve_path


def check_start(
    problem: PlanProblem, zone: dt.tzinfo | None, field: str = "start_state", fleet: bool = False
) -> dt.datetime | None:
    """The departure from the van's position in the round's zone, or None without a start
    state; raises :class:`core.exceptions.InvalidParameterError` naming the field (``field``
    and below) for what cannot be planned from it. A round (not ``fleet``) of one trip
    carries every stop from where it is; a van that may reload carries no more than its
    payload."""
    state = problem.start_state
    if state is None:
        return None
    if problem.matrix is not None:
        raise InvalidParameterError(
            "a client matrix has no row for the van's position: leave out matrix (the "
            f"planner estimates the legs or asks its router) or {field}",
            field,
        )
    battery = problem.van.battery
    if state.soc < battery.min_soc + MIN_SOC_WINDOW:
        raise InvalidParameterError(
            f"soc {state.soc:g} is less than {MIN_SOC_WINDOW:g} above the reserve min_soc "
            f"{battery.min_soc:g}: the van cannot plan a round on it",
            f"{field}.soc",
        )
    delivered = sum(stop.delivery_kg for stop in problem.stops)
    one_load = not fleet and problem.max_trips == 1  # else it may come back to reload
    if one_load and state.payload_kg is not None and state.payload_kg < delivered - 1e-9:
        raise InvalidParameterError(
            f"payload_kg {state.payload_kg:g} is less than the {delivered:g} kg the stops left "
            "take",
            f"{field}.payload_kg",
        )
    if state.payload_kg is not None and state.payload_kg > problem.van.payload_kg:
        raise InvalidParameterError(
            f"payload_kg {state.payload_kg:g} is more than the van's payload_kg "
            f"{problem.van.payload_kg:g}: nothing is loaded on the way",
            f"{field}.payload_kg",
        )
    if not fleet:
        check_start_id(problem)
    moment = state.time.astimezone(zone)
    if moment.date() != problem.date:
        raise InvalidParameterError(
            f"{state.time.isoformat()} is on {moment.date()} in the round's zone, not on the "
            f"round's date {problem.date}",
            f"{field}.time",
        )
    return moment


def check_start_id(problem: RoundFields, field: str = "start_state") -> None:
    """No place of a round under way is called :data:`START_ID`, the name of the van's
    position in its tour and legs (``["start", "start", …]`` would not say which is which)."""
    places = [("depot", problem.depot), *((f"stops[{k}]", s) for k, s in enumerate(problem.stops))]
    places += [(f"chargers[{k}]", c) for k, c in enumerate(problem.chargers)]
    for name, place in places:
        if place.id == START_ID:
            raise InvalidParameterError(
                f"the id '{START_ID}' names the van's position when it plans from {field}; "
                "call this place otherwise",
                f"{name}.id",
            )


def under_way(problem: PlanProblem) -> PlanProblem:
    """The round with the van's battery as it is now (the start state's charge)."""
    state = problem.start_state
    if state is None:
        return problem
    van = problem.van
    battery = van.battery.model_copy(update={"initial_soc": state.soc})
    return problem.model_copy(update={"van": van.model_copy(update={"battery": battery})})


def start_payload_kg(problem: PlanProblem) -> float:
    """What the van carries when it sets off: its payload, or the start state's [kg]."""
    state = problem.start_state
    if state is None or state.payload_kg is None:
        return problem.van.payload_kg
    return state.payload_kg


def box_start_c(problem: PlanProblem) -> float | None:
    """The box's temperature when a van under way sets off (the set-point unless given);
    None when it leaves the depot."""
    state = problem.start_state
    if state is None:
        return None
    if state.box_temperature_c is None:
        return problem.van.cargo_box.setpoint_c
    return state.box_temperature_c


def product_start_c(problem: PlanProblem) -> float | None:
    """The goods' temperature when a van under way sets off, if the start state says; None:
    as loaded."""
    state = problem.start_state
    return None if state is None else state.product_temperature_c


def path_tour(cost: NDArray[np.int64], effort: Effort, keep_order: bool) -> Tour:
    """The shortest path from the last place of ``cost`` (the van's position) through the
    stops to place 0 (the depot), as a tour of the places' indices from the start to the
    depot; its cost and status are the path's."""
    n = cost.shape[0]
    return solve_path(cost, [n - 1, *range(1, n - 1), 0], effort, keep_order)
