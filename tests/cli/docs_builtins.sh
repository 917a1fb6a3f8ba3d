#!/usr/bin/env bash
# docs/builtins.md is exactly `gale builtins --markdown`: the docs come from the table.
source "$(dirname "$0")/lib.bash"

if ! diff -u "$SRC/docs/builtins.md" <("$GALE" builtins --markdown); then
    echo "docs/builtins.md is out of date: regenerate with  build/cli/gale builtins --markdown > docs/builtins.md"
    exit 1
fi
echo "docs_builtins: ok"
