"""Charging in a fleet's day: the E-VRPTW search in the product, its routes verified by the
full simulation with their charges fitted and the charge points booked (:mod:`.fleet_charging`)."""
