"""Which routes can go electric, with which battery — the paper's second use, "the first design
of the necessary battery capacity": each of the fleet's routes as it was driven, simulated for
each candidate van on every day it is driven in a year (:mod:`.study`), summed up per route and
per fleet (:mod:`.summary`); the request and the answer (:mod:`.model`)."""
