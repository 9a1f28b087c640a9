"""The day as the fleet search sees it (:class:`~core.planning.search.day.FleetDay`), what
its estimates say a van can do (:mod:`.feasibility`), and the repair of a route its
simulation refuses (:mod:`.repair`)."""
