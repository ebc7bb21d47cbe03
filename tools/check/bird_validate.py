#!/usr/bin/python3
"""Validates a BiRD universal BRDF JSON file against a folder of JSON schema files.

    /usr/bin/python3 tools/check/bird_validate.py SCHEMA_DIR FILE

SCHEMA_DIR holds the BiRD project's schema files (brdf_json_schema_v1.0.json at the top, the
others referred to by their $id URLs), or any draft 2020-12 schema whose top level is named there
with --top (e.g. tests/python/bird_required.schema.json with SCHEMA_DIR its folder). The $id
references are resolved to the files in the folder, never fetched; a file there that is not JSON
is reported and skipped. Prints each violation with its place in the file and exits 1 when there
is one, 0 when the file is valid. Needs Debian's python3-jsonschema (4.x: draft 2020-12).
docs/bird-format.md, "Checking a file".
"""

import argparse
import glob
import json
import os
import sys

import jsonschema


def load_schemas(folder):
    """{$id: schema} of the folder's JSON files (those that parse)."""
    store = {}
    for path in sorted(glob.glob(os.path.join(folder, "*.json"))):
        try:
            with open(path, encoding="utf-8") as f:
                schema = json.load(f)
        except ValueError as e:
            print(f"skipping {os.path.basename(path)}: not JSON ({e})", file=sys.stderr)
            continue
        if isinstance(schema, dict) and "$id" in schema:
            store[schema["$id"]] = schema
    return store


def violations(schema_dir, top_name, document):
    """The validation errors of `document`, in the order of their place in it."""
    with open(os.path.join(schema_dir, top_name), encoding="utf-8") as f:
        top = json.load(f)
    resolver = jsonschema.RefResolver.from_schema(top, store=load_schemas(schema_dir))
    validator = jsonschema.Draft202012Validator(top, resolver=resolver)
    return sorted(validator.iter_errors(document), key=lambda e: list(map(str, e.absolute_path)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("schema_dir")
    parser.add_argument("file")
    parser.add_argument("--top", default="brdf_json_schema_v1.0.json",
                        help="the top-level schema's file name in SCHEMA_DIR")
    args = parser.parse_args()
    with open(args.file, encoding="utf-8") as f:
        document = json.load(f)
    errors = violations(args.schema_dir, args.top, document)
    for e in errors[:50]:
        place = "/".join(map(str, e.absolute_path)) or "(top)"
        print(f"{place}: {e.message[:300]}")
    print(f"{args.file}: {len(errors)} violation(s) of {args.top}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
