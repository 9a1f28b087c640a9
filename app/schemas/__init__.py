"""Request and response models of the HTTP API, one module per resource; parameters and the
fields of a round reuse the core's definitions."""
