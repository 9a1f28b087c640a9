"""The itinerary: a van's planned day as the planning stages hand it on."""

from core.planning.itinerary import ChargeVisit, Itinerary

# places: the depot 0, stops 1–3, a charger 4
STOPS = 3
FAST = ChargeVisit(plug_s=120.0, charge_s=900.0, power_kw=150.0, open_s=[(3600.0, 7200.0)])
DEPOT = ChargeVisit(plug_s=60.0, charge_s=600.0, power_kw=22.0, reloads=True)


def test_each_position_says_what_the_van_does_there():
    day = Itinerary.of([0, 1, 4, 2, 0, 3, 0], {2: FAST})
    kinds = [day.kind(q, STOPS) for q in range(len(day.order))]
    assert kinds == ["end", "stop", "charge", "stop", "reload", "stop", "end"]
    assert [day.reloads_at(q) for q in range(len(day.order))] == [False] * 4 + [True] + [False] * 2
    # a charger in the order without a charge is passed by
    assert Itinerary.of([0, 4, 1, 0]).kind(1, STOPS) == "pass"


def test_a_charge_at_the_depot_that_reloads_is_a_return_to_reload_too():
    day = Itinerary.of([0, 1, 0, 2, 0], {2: DEPOT})
    assert day.kind(2, STOPS) == "charge" and day.reloads_at(2)
    assert day.served() == [1, 0, 2]
    assert day.stretch_ends() == [0, 2, 4]


def test_a_charge_inserted_moves_the_later_charges_along():
    day = Itinerary.of([0, 1, 0, 2, 0], {2: DEPOT}).with_charge(0, 4, FAST)
    assert day.order == (0, 4, 1, 0, 2, 0)
    assert day.charges == {1: FAST, 3: DEPOT}


def test_keeping_some_stops_keeps_the_charges_where_they_are():
    day = Itinerary.of([0, 1, 4, 2, 3, 0], {2: FAST})
    kept = day.keeping({1, 3})
    assert kept.order == (0, 1, 4, 3, 0) and kept.charges == {2: FAST}


def test_refitted_drops_a_charge_with_nothing_to_charge_but_not_the_return_to_reload():
    day = Itinerary.of([0, 4, 1, 0, 2, 0], {1: FAST, 3: DEPOT})
    idle = {1: ChargeVisit(120.0, 0.0, 150.0), 3: ChargeVisit(60.0, 0.0, 22.0, reloads=True)}
    fitted = day.refitted(idle)
    assert fitted.order == (0, 1, 0, 2, 0) and fitted.charges == {}
    assert fitted.kind(2, STOPS) == "reload"


def test_a_return_to_reload_beside_a_charge_at_the_depot_is_one_stop():
    plain = ChargeVisit(60.0, 600.0, 22.0)
    day = Itinerary.of([0, 1, 0, 0, 2, 0], {2: plain}).reloading_while_charging([3])
    assert day.order == (0, 1, 0, 2, 0)
    assert day.charges[2].reloads and day.charges[2].charge_s == 600.0


def test_a_later_departure_moves_the_opening_hours_nearer():
    day = Itinerary.of([0, 4, 1, 0], {1: FAST}).shifted(600.0)
    assert list(day.charges[1].open_s) == [(3000.0, 6600.0)]
    assert day.order == (0, 4, 1, 0)
