"""Print the app's OpenAPI document (``make openapi`` writes it to openapi/openapi.json)."""

from __future__ import annotations

import json

from app.main import app

if __name__ == "__main__":
    print(json.dumps(app.openapi(), indent=2, ensure_ascii=False))
