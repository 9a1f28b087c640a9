"""A delivery round (:mod:`.planner`): the round trip with its proof, or a fleet of one van
when stops have time windows; its returns to reload (:mod:`.reloads`)."""
