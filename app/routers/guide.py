"""The documentation site (/guide): the pages `make docs` builds from docs/ into app/guide,
served by the service itself like /docs — nothing from another host."""

from __future__ import annotations

import mimetypes
from functools import cache
from importlib.resources import files
from importlib.resources.abc import Traversable

from fastapi import APIRouter, Response
from fastapi.responses import RedirectResponse
from starlette.exceptions import HTTPException

from app.routers.viewer import files_under

router = APIRouter(include_in_schema=False)

#: What the guide's pages may load: their own files. Material's two small inline scripts and
#: KaTeX's inline styles need 'unsafe-inline'; the search runs in a worker of its own.
POLICY = (
    "default-src 'none'; script-src 'self' 'unsafe-inline'; style-src 'self' 'unsafe-inline'; "
    "img-src 'self' data:; font-src 'self' data:; connect-src 'self'; worker-src 'self'; "
    "base-uri 'self'; form-action 'none'; frame-ancestors 'none'"
)
#: The site's files that the standard table may not know (or knows differently).
MEDIA_TYPES = {".js": "text/javascript", ".woff2": "font/woff2", ".xml": "application/xml"}


@cache
def _site() -> dict[str, Traversable]:
    """Every file of the built site by its path under /guide/ (empty when it was not built)."""
    site = files("app").joinpath("guide")
    return files_under(site, lambda _: True) if site.is_dir() else {}


def _media_type(name: str) -> str:
    suffix = name[name.rfind(".") :]
    return MEDIA_TYPES.get(suffix) or mimetypes.guess_type(name)[0] or "application/octet-stream"


@router.api_route("/guide", methods=["GET", "HEAD"])
def guide_home() -> Response:
    return RedirectResponse("/guide/", status_code=308)


@router.api_route("/guide/{name:path}", methods=["GET", "HEAD"])
def guide_file(name: str) -> Response:
    site = _site()
    if not site:
        raise HTTPException(404, "the guide is not built here: run `make docs`")
    found = site.get(f"{name}index.html" if name == "" or name.endswith("/") else name)
    if found is None and f"{name}/index.html" in site:
        return RedirectResponse(f"/guide/{name}/", status_code=308)
    if found is None:
        shown = name if len(name) <= 64 else f"{name[:64]}… ({len(name):,} characters)"
        raise HTTPException(404, f"no guide page {shown!r}")
    media = _media_type(found.name)
    headers = {"Cache-Control": "no-cache"}
    if media == "text/html":
        headers["Content-Security-Policy"] = POLICY
    return Response(found.read_bytes(), media_type=media, headers=headers)
