"""Charging in a fleet's day: the E-VRPTW search in the product (:mod:`.fleet_charging`), and
the stops still left out inserted with the charges they need (:mod:`.charge_insertion`)."""
