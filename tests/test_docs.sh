#!/usr/bin/env bash
# test_docs.sh BIN_DIR - the docs quote the commands they describe
# (issue 33): every flag each tool's --help lists (each command's, for
# lftool, lflens and lfrender merge) appears on the tool's page; the README
# links every tool's page; figures a handout quotes from `lfrender
# --explain` are the ones it prints; docs/depth.md gives one BadPix0.01 for
# the default method wherever it quotes the benchmark.  Run from the
# repository root.
set -u
bin=$(cd "$1" && pwd)
pass=0 fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAILED: $*"; }

# The long flags a --help lists in its options column.
flags() { "$@" --help 2>&1 | grep -oE '^  (-[A-Za-z], )?--[a-z0-9-]+' | grep -oE -- '--[a-z0-9-]+' | sort -u; }
# page_has_flags PAGE COMMAND...: every flag of COMMAND --help on PAGE
page_has_flags() {
    local page=$1; shift
    local f n=0
    for f in $(flags "$@"); do
        n=$((n + 1))
        if grep -qE -- "$f([^a-z0-9-]|\$)" "$page"; then ok; else bad "$page lacks $f (from \`${*#$bin/} --help\`)"; fi
    done
    [ "$n" -gt 0 ] || bad "\`$* --help\` lists no flags"
}

page_has_flags docs/lfrender.md "$bin/lfrender"
page_has_flags docs/lfrender.md "$bin/lfrender" merge
for c in $("$bin/lftool" --help | sed -n '/^commands:/,/^$/p' | awk 'NR > 1 && NF { print $1 }'); do
    page_has_flags docs/lftool.md "$bin/lftool" "$c"
done
for c in info plot; do page_has_flags docs/lflens.md "$bin/lflens" "$c"; done
page_has_flags docs/grading.md "$bin/lfgrade"

# the README links every tool's page
for page in docs/lfrender.md docs/lftool.md docs/lflens.md docs/grading.md; do
    if [ -f "$page" ] && grep -q "($page)" README.md; then ok; else bad "README.md does not link $page"; fi
done
# lflens lives on its own page; realistic.md links it
if grep -q '(lflens.md)' docs/realistic.md; then ok; else bad "docs/realistic.md does not link lflens.md"; fi

# A handout's refocusable range is what --explain prints for its scene.
for readme in assignments/*/README.md; do
    dir=$(dirname "$readme")
    grep -oE 'depths [0-9.]+ m \.\. [0-9.]+ m' "$readme" | while read -r fig; do
        found=0
        for scene in "$dir"/scenes/*.pbrt; do
            "$bin/lfrender" "$scene" --explain 2>&1 | grep -qF "$fig" && found=1
        done
        [ "$found" = 1 ] || echo "MISMATCH $readme: \"$fig\" is not what lfrender --explain prints"
    done
done >"${TMPDIR:-/tmp}/test_docs.$$"
if [ -s "${TMPDIR:-/tmp}/test_docs.$$" ]; then bad "$(cat "${TMPDIR:-/tmp}/test_docs.$$")"; else ok; fi
rm -f "${TMPDIR:-/tmp}/test_docs.$$"
# ... and the handout of assignment 4 quotes one at all
if grep -qE 'depths [0-9.]+ m \.\. [0-9.]+ m' assignments/4-lightfield/README.md; then ok; else
    bad "assignments/4-lightfield/README.md quotes no refocusable range from --explain"; fi

# docs/depth.md: the default method's BadPix0.01 on backgammon is one figure
# (the results table, the variants' defaults row and the last quoted run of
# bench/lf_backgammon.sh; the text's comparisons quote it too)
table=$(grep -E '^\| `lf_lightfield_depth` \(default' docs/depth.md | awk -F'|' '{ print $5 }' | grep -oE '[0-9.]+')
defaults=$(grep -E '^\| defaults \|' docs/depth.md | awk -F'|' '{ print $5 }' | grep -oE '[0-9.]+')
run=$(grep -E 'lf_lightfield_depth \(range auto\)' docs/depth.md | tail -1 | grep -oE 'BadPix0\.01 +[0-9.]+' | grep -oE '[0-9.]+$')
text=$(tr '\n' ' ' <docs/depth.md | grep -oE 'one step: BadPix0\.01 +[0-9.]+' | grep -oE '[0-9.]+$')
if [ -n "$table" ] && [ "$table" = "$defaults" ] && [ "$table" = "$run" ] && [ "$table" = "$text" ]; then ok; else
    bad "docs/depth.md BadPix0.01 of the default method: table $table, defaults row $defaults, last run $run, text $text"; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
