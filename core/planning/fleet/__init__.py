"""A fleet's day: the request checked, the search run and its answer built (:mod:`.planner`;
the search itself is :mod:`core.planning.search.fleet`)."""
