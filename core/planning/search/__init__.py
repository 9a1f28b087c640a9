"""The searches: the day as the fleet search sees it (:class:`~core.planning.search.day.FleetDay`),
what its estimates say a van can do (:mod:`.feasibility`), the routing solver's input
(:mod:`.solver_input`), the fleet's search and its verification (:mod:`.fleet`), the repair of
a route its simulation refuses (:mod:`.repair`), the reasons of the stops left out
(:mod:`.explain`) and charging across the fleet (:mod:`.charging`)."""
