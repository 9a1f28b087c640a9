"""Prometheus metrics (``GET /metrics``, text exposition format, ``prometheus-client``):
requests by route and status, latency histograms, the solver's time, the queue in front of
the workers and the jobs by status."""

from __future__ import annotations

from collections.abc import Callable, Iterator

from prometheus_client import CollectorRegistry, Counter, Gauge, Histogram
from prometheus_client.core import GaugeMetricFamily
from prometheus_client.registry import Collector

from app.jobs.models import STATUSES

#: Latency buckets [s]: from a cached answer to a 10 s solve.
LATENCY_BUCKETS_S = (0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60)


class _JobsByStatus(Collector):
    def __init__(self, counts: Callable[[], dict[str, int]]) -> None:
        self.counts = counts

    def collect(self) -> Iterator[GaugeMetricFamily]:
        family = GaugeMetricFamily(
            "coldroute_jobs", "Jobs in the database by status.", labels=["status"]
        )
        try:
            counts = self.counts()
        except Exception:  # a database that is away shows in /readyz, not as a scrape error
            counts = {}
        for status in STATUSES:
            family.add_metric([status], counts.get(status, 0))
        yield family


class Metrics:
    """The metrics of one server (a registry of its own)."""

    def __init__(self) -> None:
        self.registry = CollectorRegistry()
        self.requests = Counter(
            "coldroute_requests",
            "HTTP requests by method, route template and status.",
            ["method", "route", "status"],
            registry=self.registry,
        )
        self.latency = Histogram(
            "coldroute_request_duration_seconds",
            "Time to answer an HTTP request, by method and route template.",
            ["method", "route"],
            buckets=LATENCY_BUCKETS_S,
            registry=self.registry,
        )
        self.solve = Histogram(
            "coldroute_solve_seconds",
            "Time the tour search took, per plan.",
            buckets=LATENCY_BUCKETS_S,
            registry=self.registry,
        )

    def observe(self, method: str, route: str, status: int, seconds: float) -> None:
        self.requests.labels(method, route, str(status)).inc()
        self.latency.labels(method, route).observe(seconds)

    def watch(
        self,
        waiting: Callable[[], float],
        busy: Callable[[], float],
        jobs: Callable[[], dict[str, int]],
    ) -> None:
        """Read the queue, the workers and the jobs when scraped."""
        Gauge(
            "coldroute_queue_depth",
            "Requests waiting for a worker.",
            registry=self.registry,
        ).set_function(waiting)
        Gauge(
            "coldroute_workers_busy",
            "Worker processes busy with a request or a job.",
            registry=self.registry,
        ).set_function(busy)
        self.registry.register(_JobsByStatus(jobs))
