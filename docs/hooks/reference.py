"""MkDocs hook: the API reference page (``reference.md``), written from the committed OpenAPI
document (``openapi/openapi.json``, which a test keeps equal to what the service serves) — each
operation with its parameters, body and statuses, then each schema with its fields, types,
rules and descriptions."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files

OPENAPI = Path(__file__).resolve().parents[2] / "openapi" / "openapi.json"
#: Constraints of a JSON Schema shown in a field's rules, with how each reads.
RULES = {
    "minimum": "≥ {}",
    "exclusiveMinimum": "> {}",
    "maximum": "≤ {}",
    "exclusiveMaximum": "< {}",
    "minLength": "at least {} characters",
    "maxLength": "at most {} characters",
    "minItems": "at least {} items",
    "maxItems": "at most {} items",
    "pattern": "matches `{}`",
}


def on_files(files: Files, config: Any) -> Files:
    page = render(json.loads(OPENAPI.read_text()))
    files.append(File.generated(config, "reference.md", content=page))
    return files


def render(spec: dict[str, Any]) -> str:
    """The reference page of an OpenAPI 3.1 document, as Markdown."""
    out = [
        "# API reference",
        "",
        f"coldroute {spec['info']['version']}, generated from `openapi/openapi.json` — the "
        "document the service serves at `/openapi.json`, and explores at `/docs` (Swagger UI, "
        "with every example) and `/redoc`. Every answer that is not a success is an "
        "`application/problem+json` document: see "
        "[errors](integrators/contract.md#errors).",
        "",
    ]
    by_tag: dict[str, list[str]] = {}
    for path, operations in spec["paths"].items():
        for method, operation in operations.items():
            tag = (operation.get("tags") or ["other"])[0]
            by_tag.setdefault(tag, []).extend(_operation(method, path, operation))
    for tag, lines in by_tag.items():
        out += [f"## {tag.capitalize()}", "", *lines]
    out += ["## Schemas", ""]
    for name, schema in spec["components"]["schemas"].items():
        out += _schema(name, schema)
    return "\n".join(out) + "\n"


def _operation(method: str, path: str, operation: dict[str, Any]) -> list[str]:
    lines = [f"### `{method.upper()} {path}`", "", f"**{operation.get('summary', '')}**", ""]
    lines += [_demote(operation.get("description", "")), ""]
    parameters = operation.get("parameters", [])
    if parameters:
        lines += ["| parameter | in | type | required | description |", "|---|---|---|---|---|"]
        for p in parameters:
            lines.append(
                f"| `{p['name']}` | {p['in']} | {_type(p.get('schema', {}))} | "
                f"{'yes' if p.get('required') else 'no'} | {_cell(p.get('description', ''))} |"
            )
        lines.append("")
    body = operation.get("requestBody")
    if body:
        kinds = [f"`{media}`: {_type(c.get('schema', {}))}" for media, c in body["content"].items()]
        lines += ["Request body — " + "; ".join(kinds) + ".", ""]
    lines += ["| status | meaning | body |", "|---|---|---|"]
    for status, response in operation.get("responses", {}).items():
        content = response.get("content", {})
        shown = "; ".join(f"`{m}` {_type(c.get('schema', {}))}" for m, c in content.items())
        lines.append(f"| {status} | {_cell(response.get('description', ''))} | {shown or '—'} |")
    return [*lines, ""]


def _schema(name: str, schema: dict[str, Any]) -> list[str]:
    lines = [f"### {name} {{#{_anchor(name)}}}", ""]
    if schema.get("description"):
        lines += [_demote(schema["description"]), ""]
    properties = schema.get("properties")
    if not properties:
        return [*lines, f"Type: {_type(schema)}.", ""]
    required = set(schema.get("required", []))
    lines += ["| field | type | required | rules | description |", "|---|---|---|---|---|"]
    for field, sub in properties.items():
        lines.append(
            f"| `{field}` | {_type(sub)} | {'yes' if field in required else 'no'} | "
            f"{_rules(sub)} | {_cell(sub.get('description', ''))} |"
        )
    return [*lines, ""]


def _type(schema: dict[str, Any]) -> str:
    """A schema's type in words, each named schema a link to its section."""
    if "$ref" in schema:
        name = schema["$ref"].rsplit("/", 1)[-1]
        return f"[{name}](#{_anchor(name)})"
    for union in ("anyOf", "oneOf"):
        if union in schema:
            return " or ".join(dict.fromkeys(_type(s) for s in schema[union]))
    if "allOf" in schema:
        return " and ".join(_type(s) for s in schema["allOf"])
    if "enum" in schema:
        return "one of " + ", ".join(f"`{json.dumps(v)}`" for v in schema["enum"])
    if "const" in schema:
        return f"`{json.dumps(schema['const'])}`"
    kind = schema.get("type", "any")
    if kind == "array":
        return f"list of {_type(schema.get('items', {}))}"
    if kind == "object" and isinstance(schema.get("additionalProperties"), dict):
        return f"map of {_type(schema['additionalProperties'])}"
    return f"{kind} ({schema['format']})" if "format" in schema else str(kind)


def _rules(schema: dict[str, Any]) -> str:
    found: list[str] = []
    for part in (schema, *schema.get("anyOf", []), *schema.get("oneOf", [])):
        found += [rule.format(_cell(str(part[k]))) for k, rule in RULES.items() if k in part]
    if "default" in schema:
        found.append(f"default `{_cell(json.dumps(schema['default']))}`")
    return ", ".join(found) or "—"


def _cell(text: str) -> str:
    """Text for one table cell: one line, its bars escaped."""
    return " ".join(text.split()).replace("|", "\\|")


def _demote(text: str) -> str:
    """A description's own headings below the page's."""
    return "\n".join(f"####{line}" if line.startswith("#") else line for line in text.splitlines())


def _anchor(name: str) -> str:
    return "schema-" + name.lower().replace("_", "-")
