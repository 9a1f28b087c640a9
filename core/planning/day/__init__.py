"""One van's day: where it sets off (:mod:`.start_state`), its places and legs (:mod:`.scene`),
the timeline of its drives, stops, charges, reloads and breaks (:mod:`.timeline`), the
simulation that verifies it (:mod:`.verify`), the estimates a search plans with
(:mod:`.estimates`) and the charges fitted into it (:mod:`.recharge`)."""
