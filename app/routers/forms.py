"""The multipart endpoints' parts: a form field's JSON text, an uploaded text file, and the
merged body validated as the JSON endpoint's request (422s naming the field, as for JSON)."""

from __future__ import annotations

import json
from typing import Any, TypeVar

from fastapi import UploadFile
from fastapi.exceptions import RequestValidationError
from pydantic import BaseModel, ValidationError

from core.exceptions import InvalidParameterError

ModelT = TypeVar("ModelT", bound=BaseModel)


def json_object(text: str, field: str) -> dict[str, Any]:
    """The JSON object a form field holds; else a 422 naming ``field``."""
    try:
        body: Any = json.loads(text)
    except ValueError as error:
        raise InvalidParameterError(f"not JSON ({error})", field) from None
    if not isinstance(body, dict):
        raise InvalidParameterError("not a JSON object", field)
    return body


async def text_of(upload: UploadFile, field: str) -> str:
    """An uploaded file's UTF-8 text (a byte-order mark dropped); else a 422 naming ``field``."""
    try:
        return (await upload.read()).decode("utf-8-sig")
    except UnicodeDecodeError:
        name = (upload.filename or "")[:60]
        raise InvalidParameterError(f"the file {name!r} is not UTF-8 text", field) from None


def validated(model: type[ModelT], merged: dict[str, Any]) -> ModelT:
    """``merged`` as ``model``: its errors named in the body, as the JSON endpoint names them."""
    try:
        return model.model_validate(merged)
    except ValidationError as error:
        raise RequestValidationError(
            [e | {"loc": ("body", *e["loc"])} for e in error.errors()], body=merged
        ) from None
