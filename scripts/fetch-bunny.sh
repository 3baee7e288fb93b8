#!/usr/bin/env bash
# Fetches the Stanford bunny from the npm package "bunny" and converts it to
# scenes/bunny/bunny.obj (gitignored: the mesh is not ours to commit).
# Idempotent and quiet: does nothing when the OBJ already exists.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
obj="$root/scenes/bunny/bunny.obj"
[ -s "$obj" ] && exit 0

if ! command -v npm >/dev/null 2>&1 || ! command -v node >/dev/null 2>&1; then
  echo "fetch-bunny: needs npm and node (e.g. apt-get install npm) to fetch the bunny" >&2
  exit 1
fi

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# Pinned version; npm checks the tarball against the registry's integrity hash.
# One try, its errors shown: without a network npm retried for over a minute, silently.
(cd "$tmp" && npm pack bunny@1.0.1 --loglevel=error --fetch-retries=0 --fetch-timeout=20000 \
   --cache "$tmp/npm-cache" >/dev/null)
tar -xzf "$tmp"/bunny-1.0.1.tgz -C "$tmp"
# Write next to the target and rename, so an interrupted run never leaves a
# truncated OBJ that the check above would take for a finished one.
node "$root/scripts/bunny_to_obj.js" "$tmp/package/index.js" "$obj.partial"
mv "$obj.partial" "$obj"
echo "fetch-bunny: wrote ${obj#"$root"/}" >&2
