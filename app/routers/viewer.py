"""The plan viewer (/viewer): one page and its script and style, served by the service itself
(nothing from another host but the configured map tiles)."""

from __future__ import annotations

import html
from functools import cache
from importlib.resources import files
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
ASSETS = {"viewer.js": "text/javascript", "viewer.css": "text/css"}


@cache
def _asset(name: str) -> str:
    return files("app.viewer").joinpath(name).read_text(encoding="utf-8")


def _tile_origin(tile_url: str) -> str:
    if not tile_url:
        return ""
    parts = urlsplit(tile_url.replace("{s}", "*"))
    return f"{parts.scheme}://{parts.netloc}"


@router.get("/viewer")
def viewer(settings: SettingsDep) -> Response:
    """The page: the tiles' URL and credit in its body's data attributes."""
    page = _asset("index.html").format(
        tile_url=html.escape(settings.tile_url, quote=True),
        tile_attribution=html.escape(settings.tile_attribution, quote=True),
    )
    policy = POLICY.format(tiles=_tile_origin(settings.tile_url)).replace("  ", " ")
    return Response(
        page,
        media_type="text/html",
        headers={"Content-Security-Policy": policy, "Cache-Control": "no-cache"},
    )


@router.get("/viewer/static/{name}")
def asset(name: str) -> Response:
    if name not in ASSETS:
        shown = name if len(name) <= 64 else f"{name[:64]}… ({len(name):,} characters)"
        raise HTTPException(404, f"no viewer asset {shown!r}")
    return Response(_asset(name), media_type=ASSETS[name], headers={"Cache-Control": "no-cache"})
