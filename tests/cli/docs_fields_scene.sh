# docs/fields.md documents every parameter of every preset with its current default: the
# parameter tables must match fields/presets/*.se (and gale evaluates the documented presets).
source "$(dirname "$0")/lib.bash" "$@"

for preset in wind ripple volume_axis; do
    file="$SRC/fields/presets/$preset.se"
    # The preset's section of the docs: from its heading to the next one.
    section=$(awk -v h="### \`$preset\`" '$0 == h { on = 1; next } /^##/ { on = 0 } on' "$SRC/docs/fields.md")
    [ -n "$section" ] || fail "docs/fields.md has no section for the $preset preset"
    while IFS= read -r line; do
        name=$(printf '%s\n' "$line" | sed -E 's/^\$([A-Za-z_][A-Za-z0-9_]*) = ([^;]*);.*/\1/')
        default=$(printf '%s\n' "$line" | sed -E 's/^\$([A-Za-z_][A-Za-z0-9_]*) = ([^;]*);.*/\2/')
        printf '%s\n' "$section" | grep -qF "| \`$name\` | \`$default\` |" ||
            fail "docs/fields.md: the $preset preset's parameter '$name' (default $default) is not documented"
    done < <(grep -E '^\$[A-Za-z_][A-Za-z0-9_]* = [^;]*;' "$file")
    # Documented parameters that the preset no longer has.
    while IFS= read -r name; do
        grep -qE "^\\\$$name = " "$file" || fail "docs/fields.md documents '$name', which $preset.se does not declare"
    done < <(printf '%s\n' "$section" | sed -nE 's/^\| `([A-Za-z_][A-Za-z0-9_]*)` \| `.*/\1/p')

    # Every preset runs from a scene with its defaults.
    printf '[[field]]\npreset = "%s"\n' "$preset" > "$preset.toml"
    run "$GALE" eval "$preset.toml" --points "$SRC/examples/02_gusts/line.csv" --checked
    expect_rc 0 "the $preset preset evaluates"
done

finish
