#!/usr/bin/env bash
# Installs the iai-callgrind runner at exactly the library's version (the two
# must match) and checks valgrind. Takes about two minutes the first time.
set -euo pipefail
version=$(sed -n 's/^iai-callgrind = "=\(.*\)"/\1/p' "$(dirname "$0")/../Cargo.toml")
if ! command -v valgrind >/dev/null; then
    echo "valgrind is missing: apt-get install valgrind" >&2
    exit 1
fi
if ! cargo install --list | grep -qx "iai-callgrind-runner v$version:"; then
    cargo install iai-callgrind-runner --version "$version" --locked
fi
echo "iai-callgrind-runner $version at $(command -v iai-callgrind-runner)"
