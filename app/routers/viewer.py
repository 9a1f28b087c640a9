"""The plan viewer (/viewer): one page, its script and style and the map and chart libraries
vendored beside them (app/viewer/vendor: Leaflet, Leaflet.markercluster, uPlot, each with its
licence), served by the service itself — nothing from another host but the configured map
tiles."""

from __future__ import annotations

import html
from collections.abc import Callable
from functools import cache
from importlib.resources import files
from importlib.resources.abc import Traversable
from urllib.parse import urlsplit

from fastapi import APIRouter, Response
from starlette.exceptions import HTTPException

from app.deps import SettingsDep

router = APIRouter(include_in_schema=False)

#: What the page may load: its own script, style and API, and images from the tile server.
POLICY = (
    "default-src 'none'; script-src 'self'; style-src 'self'; connect-src 'self'; "
    "img-src 'self' data: {tiles}; base-uri 'none'; form-action 'none'; frame-ancestors 'none'"
)
#: The media type of each kind of file the viewer serves.
MEDIA_TYPES = {".js": "text/javascript", ".css": "text/css", ".png": "image/png"}


def files_under(
    folder: Traversable, served: Callable[[str], bool], prefix: str = ""
) -> dict[str, Traversable]:
    """Every file under ``folder`` whose path ``served`` accepts, by its path under it."""
    found: dict[str, Traversable] = {}
    for entry in folder.iterdir():
        name = f"{prefix}{entry.name}"
        if entry.is_dir():
            found |= files_under(entry, served, f"{name}/")
        elif served(name):
            found[name] = entry
    return found


def _served(name: str) -> bool:
    """The viewer's own files and its libraries with their licences."""
    licence = name.rsplit("/", 1)[-1] == "LICENSE"
    return licence or any(name.endswith(suffix) for suffix in MEDIA_TYPES)


@cache
def _assets() -> dict[str, Traversable]:
    """Every file the viewer may serve by its path under /viewer/static/ — the page's own
    script and style and the vendored libraries with their licences; nothing else."""
    return files_under(files("app.viewer"), _served)


@cache
def _page() -> str:
    return files("app.viewer").joinpath("index.html").read_text(encoding="utf-8")


def _tile_origin(tile_url: str) -> str:
    if not tile_url:
        return ""
    parts = urlsplit(tile_url.replace("{s}", "*"))
    return f"{parts.scheme}://{parts.netloc}"


@router.get("/viewer")
def viewer(settings: SettingsDep) -> Response:
    """The page: the tiles' URL and credit in its body's data attributes."""
    page = _page().format(
        tile_url=html.escape(settings.tile_url, quote=True),
        tile_attribution=html.escape(settings.tile_attribution, quote=True),
    )
    policy = POLICY.format(tiles=_tile_origin(settings.tile_url)).replace("  ", " ")
    return Response(
        page,
        media_type="text/html",
        headers={"Content-Security-Policy": policy, "Cache-Control": "no-cache"},
    )


@router.get("/viewer/static/{name:path}")
def asset(name: str) -> Response:
    found = _assets().get(name)
    if found is None:
        shown = name if len(name) <= 64 else f"{name[:64]}… ({len(name):,} characters)"
        raise HTTPException(404, f"no viewer asset {shown!r}")
    media = next((t for s, t in MEDIA_TYPES.items() if name.endswith(s)), "text/plain")
    return Response(found.read_bytes(), media_type=media, headers={"Cache-Control": "no-cache"})
