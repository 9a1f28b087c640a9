"""The routing solver's input (:class:`core.routing.vrp.RoutingInput`) from the day and the
current estimates, in the solver's integer units (:mod:`core.routing.units`)."""

from __future__ import annotations

import math

import numpy as np

from core.planning.day.start_state import start_payload_kg
from core.planning.search.feasibility import Feasibility
from core.routing.pyvrp_run import above_routes
from core.routing.units import energy_units_down, energy_units_up, payload_units_down
from core.routing.vrp import RoutingInput, VehicleSpec


def routing_input(rules: Feasibility, minimize_vehicles: bool) -> RoutingInput:
    """Everything the solver needs; ``minimize_vehicles``: a van costs more than any set of
    routes, so fewer vans come first (the vans listed first drive first when as good).

    A stop no van could serve even alone (no window left, too heavy, no road) gets a window
    just past the horizon and no demand, so the solver leaves it out at once instead of
    searching for a place for it until its time limit.
    """
    day = rules.day
    kinds = list({id(e): e for e in day.estimates}.values())
    bound = max((above_routes(kind.arc_cost, len(day.shifts)) for kind in kinds), default=0)
    fixed = bound if minimize_vehicles else 0
    # one matrix per kind of van, shared by its vans (and so by the solvers' vehicle types)
    energies = {id(kind): energy_units_up(kind.energy_j) for kind in kinds}
    specs = []
    for v, shift in enumerate(day.shifts):
        estimates, budget = day.estimates[v], rules.budgets_j[v]
        start_s, end_s = day.shift_s[v]
        specs.append(
            VehicleSpec(
                arc_cost=estimates.arc_cost,
                energy=None if budget is None else energies[id(estimates)],
                energy_capacity=0 if budget is None else energy_units_down(budget),
                payload_capacity_g=payload_units_down(shift.problem.van.payload_kg),
                shift_s=(math.ceil(start_s), math.floor(end_s)),
                fixed_cost=v if day.starts[v] else fixed + v,  # one under way drives anyway
                wait_cost_per_s=estimates.wait_cost_per_s,
                max_reloads=shift.problem.max_trips - 1,
                reload_s=math.ceil(shift.problem.reload_minutes * 60),
                start=day.starts[v],
                initial_load_g=payload_units_down(shift.problem.van.payload_kg)
                - payload_units_down(start_payload_kg(shift.problem)),
                forbidden=day.forbidden(v),
            )
        )
    never = [(day.horizon_s + 1, day.horizon_s + 1)]
    windows = []
    for node, place in enumerate(day.windows_s):
        inside = [(max(math.ceil(a), 0), min(math.floor(b), day.horizon_s)) for a, b in place]
        kept = [(a, b) for a, b in inside if a <= b]
        hopeless = node > 0 and (
            node not in day.stop_nodes  # a van's position: where it sets off, not a stop
            or node in day.unreachable
            or (place and not kept)
            or all(rules.alone(v, node) for v in day.vans_for(node))
        )
        windows.append(never if hopeless else kept)
    demand = np.where([w is never for w in windows], 0, day.demand_g)
    return RoutingInput(
        travel_s=rules.travel_s,
        service_s=day.service_s.astype(np.int64),
        windows_s=windows,
        demand_g=demand.astype(np.int64),
        vehicles=specs,
        horizon_s=day.horizon_s,
        drop_penalty=bound * (len(day.shifts) + 2),
    )
