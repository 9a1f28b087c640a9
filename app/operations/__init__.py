"""The service's operations, one module each — request → core problem → answer — used alike
by the routers (in a worker process) and by the jobs (:mod:`app.operations.kinds`, the
registry of what runs as a job)."""
