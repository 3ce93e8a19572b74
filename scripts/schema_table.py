#!/usr/bin/env python3
"""Prints the key table of a grip JSON Schema as Markdown: one row per key path with its
type, default, units and description, per body model and shape type where they differ.

    scripts/schema_table.py [schemas/scene.schema.json] > keys.md

Standard library only. Paths: `a.b` for object keys, `a[]` for array items, `a.<name>` for
keys the user names (load cases, obstacles). Units come from the "Units: ..." sentence of a
description.
"""
import json
import re
import sys
from pathlib import Path

UNITS = re.compile(r"\s*Units: ([^.]*(?:\.\d[^.]*)*)\.\s*")


def follow(ref, root):
    node = root
    for part in ref.lstrip("#").strip("/").split("/"):
        if part:
            node = node[part.replace("~1", "/").replace("~0", "~")]
    return node


def resolve(schema, root):
    """The subschema a $ref names (local references only). A schema that only wraps one
    reference, {"allOf": [{"$ref": ...}], "description": ..., "default": ...}, is the
    referenced one with those annotations."""
    for _ in range(32):
        if not isinstance(schema, dict):
            return schema
        if "$ref" in schema:
            schema = follow(schema["$ref"], root)
            continue
        wrapped = schema.get("allOf", [])
        if len(wrapped) == 1 and isinstance(wrapped[0], dict) and set(wrapped[0]) == {"$ref"} and "type" not in schema:
            notes = {k: v for k, v in schema.items() if k != "allOf"}
            schema = {**resolve(wrapped[0], root), **notes}
            continue
        return schema
    return schema


def forbidden(schema):
    return isinstance(schema, dict) and schema.get("not") == {}


def type_text(schema, root):
    schema = resolve(schema, root)
    if not isinstance(schema, dict):
        return ""
    if "const" in schema:
        return json.dumps(schema["const"])
    if "enum" in schema:
        return " \\| ".join(json.dumps(v) for v in schema["enum"])
    types = schema.get("type", "")
    types = types if isinstance(types, list) else [types] if types else []
    if types == ["array"] and schema.get("minItems") == 2 == schema.get("maxItems"):
        items = schema.get("items", {})
        items = items if isinstance(items, list) else [items, items]
        kinds = [resolve(i, root).get("type", "") if isinstance(resolve(i, root), dict) else "" for i in items]
        return "[x, y]" if kinds == ["number", "number"] else f"[{kinds[0]}, {kinds[1]}]"
    words = []
    for t in types:
        if t == "array" and isinstance(schema.get("items"), dict):
            inner = type_text(schema["items"], root)
            words.append(f"array of {inner}" if inner else "array")
        else:
            words.append(t)
    text = " or ".join(words)
    if "pattern" in schema and "string" in types:
        text += f" matching {schema['pattern']}".replace("|", "\\|")
    return text


def bounds_text(schema):
    parts = []
    for key, sign in (("minimum", ">="), ("exclusiveMinimum", ">"), ("maximum", "<="), ("exclusiveMaximum", "<")):
        if key in schema:
            parts.append(f"{sign} {schema[key]}")
    return ", ".join(parts)


def condition_text(schema, prefix=""):
    """`model = continuum` for the conditions that tell models and shapes apart."""
    if not isinstance(schema, dict):
        return None
    parts = []
    for key, sub in schema.get("properties", {}).items():
        if isinstance(sub, dict) and "const" in sub:
            parts.append(f"{prefix}{key} = {sub['const']}")
        elif isinstance(sub, dict):
            inner = condition_text(sub, f"{prefix}{key}.")
            if inner:
                parts.append(inner)
    if not parts and schema.get("required") and set(schema) <= {"required"}:
        parts.append(" and ".join(f"{prefix}{k} given" for k in schema["required"]))
    return ", ".join(parts) or None


def negate(text):
    return f"not ({text})" if text else None


def documented(schema, root):
    """Whether a conditional branch adds keys worth a row (not only rules)."""
    target = resolve(schema, root)
    if isinstance(schema, dict) and "$ref" in schema:
        return True
    props = target.get("properties", {}) if isinstance(target, dict) else {}
    return any(isinstance(resolve(p, root), dict) and "description" in resolve(p, root) for p in props.values())


class Table:
    def __init__(self, root):
        self.root = root
        self.rows = []
        self.seen = set()

    def row(self, path, schema, when):
        schema = resolve(schema, self.root)
        if not isinstance(schema, dict) or (path, when) in self.seen:
            return
        self.seen.add((path, when))
        description = schema.get("description", "")
        units = ""
        match = UNITS.search(description)
        if match:
            units = match.group(1)
            description = UNITS.sub(" ", description).strip()
        default = json.dumps(schema["default"]) if "default" in schema else ""
        kind = type_text(schema, self.root)
        bounds = bounds_text(schema)
        if bounds:
            kind = f"{kind} ({bounds})" if kind else bounds
        self.rows.append((path, when or "", kind, default, units, description))

    def walk(self, schema, path, when, emit=True):
        schema = resolve(schema, self.root)
        if not isinstance(schema, dict):
            return
        if emit and path:
            self.row(path, schema, when)
        for key, sub in schema.get("properties", {}).items():
            if forbidden(sub):
                continue
            target = resolve(sub, self.root)
            if isinstance(target, dict) and "const" in target and len(target) == 1:
                continue  # the discriminator repeated inside a model's or shape's branch
            self.walk(sub, f"{path}.{key}" if path else key, when)
        items = schema.get("items")
        if isinstance(items, dict) and resolve(items, self.root).get("properties") is not None:
            self.walk(items, f"{path}[]", when, emit=False)
        elif isinstance(items, dict) and "allOf" in items:
            self.walk(items, f"{path}[]", when, emit=False)
        extra = schema.get("additionalProperties")
        if isinstance(extra, dict) and not forbidden(extra) and extra:
            self.walk(extra, f"{path}.<name>", when)
        for sub in schema.get("allOf", []):
            self.branch(sub, path, when)
        self.branch(schema, path, when, own=True)

    def branch(self, schema, path, when, own=False):
        if not isinstance(schema, dict):
            return
        if "if" not in schema:
            if not own:
                self.walk(schema, path, when, emit=False)
            return
        condition = condition_text(schema["if"])
        for key, text in (("then", condition), ("else", negate(condition))):
            if key in schema and text and documented(schema[key], self.root):
                combined = f"{when}; {text}" if when else text
                self.walk(schema[key], path, combined, emit=False)


def main():
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "schemas" / "scene.schema.json"
    root = json.loads(path.read_text())
    table = Table(root)
    table.walk(root, "", None, emit=False)
    print(f"| key | when | type | default | units | description |")
    print(f"|---|---|---|---|---|---|")
    for row in table.rows:
        print("| " + " | ".join(cell.replace("|", "\\|") if i != 2 else cell for i, cell in enumerate(row)) + " |")


if __name__ == "__main__":
    main()
