"""A fleet's day: the search and its verification (:mod:`.planner`), the routing solver's
input (:mod:`.solver_input`), the reasons of the stops it leaves out (:mod:`.explain`)."""
