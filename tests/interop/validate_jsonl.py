#!/usr/bin/env python3
"""Validates every line of a JSON-lines file against a JSON Schema (Draft 2020-12) with Debian's
python3-jsonschema, an implementation independent of fieldguard's writer.

    validate_jsonl.py SCHEMA FILE
    FILE: 120 lines valid; 87 with obstacles, 120 with a decision, 0 with fusion

Exits 1 naming the first invalid lines (at most 5), 2 when the schema itself is not valid.
"""
import json
import sys

import jsonschema


def main():
    schema_path, data_path = sys.argv[1], sys.argv[2]
    with open(schema_path, encoding="utf-8") as f:
        schema = json.load(f)
    try:
        jsonschema.Draft202012Validator.check_schema(schema)
    except jsonschema.SchemaError as e:
        print(f"{schema_path}: not a valid Draft 2020-12 schema: {e.message}")
        return 2
    validator = jsonschema.Draft202012Validator(schema)
    lines = bad = with_obstacles = with_decision = with_fusion = 0
    with open(data_path, encoding="utf-8") as f:
        for number, text in enumerate(f, start=1):
            lines += 1
            try:
                line = json.loads(text)
            except json.JSONDecodeError as e:
                bad += 1
                if bad <= 5:
                    print(f"{data_path}:{number}: not JSON: {e}")
                continue
            errors = sorted(validator.iter_errors(line), key=lambda e: list(e.path))
            if errors:
                bad += 1
                if bad <= 5:
                    for e in errors[:3]:
                        where = "/".join(str(p) for p in e.path) or "(line)"
                        print(f"{data_path}:{number}: {where}: {e.message}")
                continue
            with_obstacles += 1 if line.get("obstacles") else 0
            with_decision += 1 if "decision" in line else 0
            with_fusion += 1 if "fusion" in line else 0
    if bad:
        print(f"{data_path}: {bad} of {lines} lines invalid")
        return 1
    print(f"{data_path}: {lines} lines valid; {with_obstacles} with obstacles, {with_decision} with a decision, "
          f"{with_fusion} with fusion")
    return 0


if __name__ == "__main__":
    sys.exit(main())
