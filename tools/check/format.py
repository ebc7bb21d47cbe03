#!/usr/bin/env python3
"""Checks that the C++ sources are as clang-format writes them (.clang-format at the root).

Usage: format.py [--clang-format PROGRAM] [--fix] FOLDER...
  Runs `clang-format --dry-run -Werror` on every .cc and .h file under the given folders (relative
  to the working directory) and prints the files that differ, then their count. Exit status 1
  when any differs (or clang-format is missing: deploy/install-deps.sh installs it), 0 otherwise.
  With --fix the files are rewritten in place instead (clang-format -i).
"""
import argparse
import os
import shutil
import subprocess
import sys

SOURCE_SUFFIXES = (".cc", ".h")


def sources(folders):
    for folder in folders:
        for root, dirs, files in os.walk(folder):
            dirs[:] = sorted(d for d in dirs if not d.startswith((".", "build")))
            for name in sorted(files):
                if name.endswith(SOURCE_SUFFIXES):
                    yield os.path.join(root, name)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clang-format", default="clang-format")
    parser.add_argument("--fix", action="store_true")
    parser.add_argument("folders", nargs="+")
    args = parser.parse_args()
    program = shutil.which(args.clang_format)
    if program is None:
        print(f"format.py: {args.clang_format} not found: run deploy/install-deps.sh "
              "(Debian's clang-format)", file=sys.stderr)
        return 1
    files = list(sources(args.folders))
    if not files:
        print(f"format.py: no .cc or .h files under {' '.join(args.folders)}", file=sys.stderr)
        return 1
    differ = []
    for path in files:
        if args.fix:
            subprocess.run([program, "-i", path], check=True)
            continue
        run = subprocess.run([program, "--dry-run", "-Werror", path], capture_output=True,
                             text=True)
        if run.returncode != 0:
            differ.append(path)
            print(f"{path}: not as clang-format writes it (fix: {program} -i {path})")
    print(f"{len(differ)} of {len(files)} files differ from clang-format's layout")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
