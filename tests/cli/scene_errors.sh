# Bad scenes: every problem reported as file:line:col: error: message with the line, a caret and
# notes ("did you mean"), exit 1; unreadable scenes or expression files exit 3; bad --set paths
# name the --set; errors inside expressions point into the expression (or the scene's inline text).
source "$(dirname "$0")/lib.bash" "$@"

cat > bad.toml <<'TOML'
[scene]
fps = "fast"

[windicator]
sped = 3

[[gust]]
travel_speed = -1

[[field]]
name = "main"
preset = "wnd"
TOML
run "$GALE" eval bad.toml
expect_rc 1 "a bad scene"
expect_eq "$(printf '%s\n' "$ERR" | sed -n 1p)" "bad.toml:2:7: error: scene.fps must be a number, not a string" "first error"
expect_eq "$(printf '%s\n' "$ERR" | sed -n 2p)" '    fps = "fast"' "its line"
expect_eq "$(printf '%s\n' "$ERR" | sed -n 3p)" "          ^" "its caret"
expect_match "$ERR" "^bad.toml:5:1: error: unknown key 'sped' in \[windicator\]" "unknown key"
expect_match "$ERR" "^note: did you mean 'speed'\?" "did you mean"
expect_match "$ERR" "^bad.toml:8:16: error: gust 0: travel_speed must be positive" "bad value"
expect_match "$ERR" "^bad.toml:12:10: error: unknown preset 'wnd'" "unknown preset"
expect_match "$ERR" "^note: presets: ripple, volume_axis, wind" "the presets listed"
expect_eq "$OUT" "" "nothing on stdout"
run "$GALE" check bad.toml
expect_rc 1 "check a bad scene"
expect_match "$ERR" "^bad.toml:12:10: error: unknown preset" "check reports the same"

# Unknown parameters of a field's expression: at the key, with the declared ones.
printf '$gain = 2; # 0, 10\n[$gain, 0, 0]\n' > g.se
printf '[[field]]\nexpr = "g.se"\nparams = { gian = 1 }\n' > p.toml
run "$GALE" eval p.toml
expect_rc 1 "an unknown parameter"
expect_match "$ERR" "^p.toml:3:12: error: 'gian' is not a parameter of g.se" "at the key"
expect_match "$ERR" "^note: its parameters: gain" "the declared parameters"
run "$GALE" eval p.toml --set field.0.params.gain=3
expect_rc 1 "errors in the file are reported even with a good --set"

# --set problems name the --set.
printf '[[field]]\nname = "main"\nexpr = "g.se"\n' > ok.toml
run "$GALE" eval ok.toml --set field.mian.params.gain=1
expect_rc 1 "--set of an unknown field"
expect_match "$ERR" "^--set field.mian.params.gain=1: error: the scene has no \[\[field\]\] named 'mian'" "names the --set"
expect_match "$ERR" "^note: did you mean 'main'\?" "did you mean"
run "$GALE" eval ok.toml --set windicator.speed=fast
expect_rc 1 "--set with a bad value"
expect_match "$ERR" "^--set windicator.speed=fast: error: windicator.speed must be" "bad value"
run "$GALE" eval ok.toml --set speed=3
expect_rc 1 "--set without a section"
expect_match "$ERR" "unknown scene section 'speed'" "unknown section"

# Errors in expressions: in the file, or at their place in the scene for inline text.
printf '[[field]]\nexpr = "e.se"\n' > e.toml
printf 'v = [1, 0, 0];\nv * nosuch\n' > e.se
run "$GALE" eval e.toml
expect_rc 1 "an expression error"
expect_match "$ERR" "^e.se:2:5: error: unknown variable 'nosuch'" "in the expression file"
printf '[[field]]\nsource = "$P * oops"\n' > i.toml
run "$GALE" check i.toml
expect_rc 1 "an inline expression error"
expect_match "$ERR" "^i.toml:2:16: error: unknown variable 'oops'" "at its place in the scene"

# TOML syntax errors, missing files.
printf '[scene]\nfps = = 2\n' > syntax.toml
run "$GALE" eval syntax.toml
expect_rc 1 "a TOML syntax error"
expect_match "$ERR" "^syntax.toml:2:[0-9]+: error: " "at its line"
run "$GALE" eval missing.toml
expect_rc 3 "a missing scene"
expect_match "$ERR" "missing.toml: error: cannot read the scene" "says so"
printf '[[field]]\nexpr = "nope.se"\n' > m.toml
run "$GALE" eval m.toml
expect_rc 3 "a missing expression file"
expect_match "$ERR" "^m.toml:2:8: error: field 'field0': cannot read 'nope.se'" "at the expr key"

# Scene-only usage errors.
run "$GALE" eval ok.toml --disasm
expect_rc 2 "--disasm with a scene"
run "$GALE" eval ok.toml --type float
expect_rc 2 "--type float with a scene"

finish
