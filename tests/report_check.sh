#!/usr/bin/env bash
# runout report on the demo (test report.demo; label integration): the bundled In den Arelen scenario
# at its 10 m, then its report as A4 and as A3, opened with poppler's tools: the page count and size,
# the parameter block's text, every map's raster at 300 dpi (pdfimages), the scale written on the
# maps; the scenario's outputs.report gives the same report at the end of the run; a folder that is
# not a run on terrain is refused with its name and leaves no file.
# Usage: report_check.sh RUNOUT SOURCE_DIR
set -euo pipefail
runout=$1 src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "report_check: $*" >&2; exit 1; }
for t in pdfinfo pdftotext pdfimages; do command -v $t > /dev/null || fail "$t is missing (Debian's poppler-utils)"; done
"$runout" run "$src/scenarios/in-den-arelen.json" --out "$tmp/run" --quiet > /dev/null
"$runout" report "$tmp/run" --out "$tmp/report.pdf" | tee "$tmp/report.txt"
info=$(pdfinfo "$tmp/report.pdf")
pages=$(echo "$info" | awk '/^Pages:/ {print $2}')
[ "$pages" -ge 7 ] || fail "$pages pages (expected the summary, five maps and the profile)"
echo "$info" | grep -q "Page size: *841.89 x 595.27[0-9]* pts (A4)" || fail "not A4 landscape: $(echo "$info" | grep 'Page size')"
pdftotext -layout "$tmp/report.pdf" "$tmp/report.txt"
for text in "Parameters" "friction: Coulomb, δ = 15°, φ = 20°" "density: 300 kg/m³" "Mass balance" "Points of interest" \
            "farmhouse (destroyed 1968)" "Pressure zones" "scale 1:" "runout" "DEM: davos_srtm3.tif" \
            "blue: 3 – 30 kPa" "red: ≥ 30 kPa"; do  # the last two: the pressure map's zone boundaries in its legend
  grep -qF "$text" "$tmp/report.txt" || fail "the report's text lacks '$text'"
done
# Every raster image at 300 dpi (one per map page).
pdfimages -list "$tmp/report.pdf" | awk 'NR > 2 {print $13, $14}' > "$tmp/ppi.txt"
[ "$(wc -l < "$tmp/ppi.txt")" -ge 5 ] || fail "fewer than five images: $(cat "$tmp/ppi.txt")"
while read -r x y; do
  [ "$x" -ge 299 ] && [ "$x" -le 301 ] && [ "$y" -ge 299 ] && [ "$y" -le 301 ] || fail "an image at $x x $y ppi"
done < "$tmp/ppi.txt"
# A3.
"$runout" report "$tmp/run" --out "$tmp/a3.pdf" --paper a3 > /dev/null
pdfinfo "$tmp/a3.pdf" | grep -q "Page size: *1190.55 x 841.89 pts (A3)" || fail "not A3 landscape: $(pdfinfo "$tmp/a3.pdf" | grep 'Page size')"
# The output option: the same report at the end of the run (paths made absolute for the copy).
/usr/bin/python3 - "$src/scenarios/in-den-arelen.json" "$tmp/with-report.json" <<'PY'
import json, os, sys
src, dst = sys.argv[1], sys.argv[2]
s = json.load(open(src))
base = os.path.dirname(os.path.abspath(src))
s["dem"]["path"] = os.path.join(base, s["dem"]["path"])
s["area_of_interest"]["path"] = os.path.join(base, s["area_of_interest"]["path"])
for r in s["releases"]:
    r["path"] = os.path.join(base, r["path"])
s["grid"]["resolution_m"] = 30
s["outputs"]["report"] = "a4"
json.dump(s, open(dst, "w"))
PY
"$runout" run "$tmp/with-report.json" --out "$tmp/run30" --quiet > /dev/null
[ -f "$tmp/run30/report.pdf" ] || fail "outputs.report wrote no report.pdf"
grep -q '"report.pdf"' "$tmp/run30/run.json" || fail "run.json does not list report.pdf"
pdfinfo "$tmp/run30/report.pdf" | grep -q "Pages: *[7-9]" || fail "outputs.report's PDF has not the pages of a report"
# A report that cannot be made loses no run: without max_depth.tif (outputs.rasters) the run ends
# well, with a note in run.json, and neither report.pdf nor its part is left or listed.
/usr/bin/python3 - "$tmp/with-report.json" "$tmp/no-depth.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["outputs"]["rasters"] = ["max_speed", "max_pressure"]
json.dump(s, open(sys.argv[2], "w"))
PY
"$runout" run "$tmp/no-depth.json" --out "$tmp/run-nodepth" --quiet > /dev/null 2>&1 || fail "a run whose report cannot be made failed"
[ ! -e "$tmp/run-nodepth/report.pdf" ] && [ ! -e "$tmp/run-nodepth/report.pdf.part" ] || fail "a report that could not be made left a file"
grep -q '"report.pdf"' "$tmp/run-nodepth/run.json" && fail "run.json lists a report that is not there"
grep -q 'report.pdf not written (outputs.report)' "$tmp/run-nodepth/run.json" || fail "run.json does not say why the report is missing"
# The 3D engine's run writes no report itself: outputs.report refused, named.
/usr/bin/python3 - "$src/scenarios/in-den-arelen-3d-regress.json" "$tmp/vof-report.json" <<'PY'
import json, os, sys
src, dst = sys.argv[1], sys.argv[2]
s = json.load(open(src))
base = os.path.dirname(os.path.abspath(src))
for block in ("dem", "area_of_interest"):
    if block in s: s[block]["path"] = os.path.join(base, s[block]["path"])
for r in s["releases"]:
    r["path"] = os.path.join(base, r["path"])
s.setdefault("outputs", {})["report"] = "a4"
json.dump(s, open(dst, "w"))
PY
set +e
"$runout" run "$tmp/vof-report.json" --out "$tmp/vof" --quiet > /dev/null 2> "$tmp/vof.txt"
rc=$?
set -e
[ "$rc" -eq 4 ] && grep -q "outputs.report" "$tmp/vof.txt" || fail "the 3D engine with outputs.report: exit $rc, $(cat "$tmp/vof.txt")"
# Not a run on terrain: refused, named, no file left.
set +e
"$runout" report "$src/docs" --out "$tmp/bad.pdf" 2> "$tmp/bad.txt"
rc=$?
set -e
[ "$rc" -eq 4 ] || fail "a folder without run.json gave exit $rc"
grep -q "run.json is missing" "$tmp/bad.txt" || fail "the error does not name run.json: $(cat "$tmp/bad.txt")"
[ ! -e "$tmp/bad.pdf" ] && [ ! -e "$tmp/bad.pdf.part" ] || fail "a failed report left a file"
echo "report_check: ok ($pages pages)"
