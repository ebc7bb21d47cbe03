#!/usr/bin/env bash
# The repository stands alone: its text points at its own reference pages (docs/), never at
# files outside the repository, and every such pointer leads somewhere.
#   1. No file names the shared reference or seed folders that lived beside the repository.
#   2. Every docs/<page>.md that a file names exists.
#   3. Every relative link in a Markdown file ([text](path)) resolves.
# Usage: tests/docs/check_docs.sh SOURCE_DIR
set -uo pipefail

src="${1:?usage: check_docs.sh SOURCE_DIR}"
cd "$src" || exit 2
status=0
fail() {
  echo "check_docs: $*" >&2
  status=1
}

# Every text file of the source tree (not .git, not build trees, not node_modules).
files() {
  find . \( -name .git -o -name node_modules -o -name .cache -o -name 'build*' -type d \
    -o -type d -exec test -e '{}/CMakeCache.txt' \; \) -prune -o -type f -print |
    sed 's|^\./||' | sort
}
mapfile -t all < <(files)
mapfile -t text < <(printf '%s\n' "${all[@]}" | xargs -d '\n' grep -IlE '' 2>/dev/null)

# 1. Nothing outside the repository.
outside='shared/(reference|seed)|[.][.]/shared'
while IFS= read -r hit; do
  fail "points outside the repository (use docs/): $hit"
done < <(printf '%s\n' "${text[@]}" | xargs -d '\n' grep -HnE "$outside" 2>/dev/null)

# 2. docs/<page>.md named anywhere exists.
while IFS=: read -r file page; do
  [[ -f "$page" ]] || fail "$file names $page, which does not exist"
done < <(printf '%s\n' "${text[@]}" | xargs -d '\n' grep -HoE '(^|[^A-Za-z0-9_/.-])docs/[A-Za-z0-9_-]+[.]md' 2>/dev/null |
  sed -E 's|:[^:]*docs/|:docs/|' | sort -u)

# 3. Relative Markdown links resolve.
for md in "${text[@]}"; do
  [[ "$md" == *.md ]] || continue
  dir="$(dirname "$md")"
  while IFS= read -r target; do
    target="${target%%#*}"
    [[ -z "$target" || "$target" =~ ^[a-z]+: ]] && continue
    [[ -e "$dir/$target" ]] || fail "$md links to $target, which does not exist"
  done < <(grep -oE '\]\([^) ]+\)' "$md" | sed -E 's/^\]\((.*)\)$/\1/')
done

pages=$(ls docs/*.md 2>/dev/null | wc -l)
[[ "$pages" -ge 5 ]] || fail "docs/ holds $pages pages; expected README, geometry, interpolation, pr650, stage-modbus"
[[ $status -eq 0 ]] && echo "check_docs: ${#text[@]} text files, $pages pages in docs/: ok"
exit $status
