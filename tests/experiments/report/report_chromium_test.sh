#!/usr/bin/env bash
# Opens the report of a tiny sweep in headless Chromium and fails if the page logs an error, an
# image fails to load, or a plot (or the page) is blank. Registered with ctest by
# tests/CMakeLists.txt; by hand:
#   tests/experiments/report/report_chromium_test.sh build/bin/testbed /tmp/report-chromium-test
#
# Input: made here by `testbed sweep tests/experiments/fixtures/report-smoke.json` (16 tiny
# jobs, four stages x two light counts x two views, i.e. four comparable groups, with a
# published-figures entry), then `testbed report`.
#
# What the loaded page must show (checked on the DOM Chromium dumps): one section per comparable
# group (four: a view is a setting like the light count, never pooled) with exactly one Pareto
# plot each (img data-kind="pareto"), the shared-scale maps of every job of the group; the
# "Across views" section with one family per light count, each aggregating the four stages over
# the two views (a row per stage) with its per-view rows in a closed toggle (<details>, eight
# rows); the results table with the flip (ꟻLIP) column among the main columns and the others
# behind the toggle, and -- when ꟻLIP is missing for some job (images that could not be compared) -- the
# visible note saying why; inferred's reduced-resolution light counts are explained in a note.
# Failed jobs, null metrics and single-valued axes are covered by tests/experiments/report/report_test.cpp.
#
# The page's inline script (experiments/report/ReportCommand.h, pageCheckScript) writes
# "PAGE-CHECK: OK (N images)" into #page-check after the load event, or "PAGE-CHECK: FAILED" and
# the images that did not load / script errors; --dump-dom prints the DOM after loading. Any
# console message or uncaught exception is caught from Chromium's log (--enable-logging=stderr). The plot PNGs
# and the screenshot must have many distinct colours (a blank or one-colour image fails).
#
# Chromium missing is a failure, not a skip: ./run.sh installs Debian's chromium.
set -euo pipefail

testbed=${1:?usage: $0 TESTBED_BINARY WORK_DIR}
work=${2:?usage: $0 TESTBED_BINARY WORK_DIR}
here=$(cd "$(dirname "$0")/.." && pwd) # tests/experiments
sweep_file=$here/fixtures/report-smoke.json

fail() { echo "report_chromium_test: FAIL: $*" >&2; exit 1; }

chromium=$(command -v chromium || command -v chromium-browser || true)
[ -n "$chromium" ] || fail "chromium not found on PATH (install Debian package chromium; ./run.sh does)"
python=
for candidate in /usr/bin/python3 python3; do
    if "$candidate" -c "import matplotlib, numpy" 2>/dev/null; then python=$candidate; break; fi
done
[ -n "$python" ] || fail "no python3 with matplotlib (install Debian package python3-matplotlib)"

rm -rf "$work"
mkdir -p "$work"
results=$work/results

echo "report_chromium_test: testbed sweep $sweep_file --out $results"
"$testbed" sweep "$sweep_file" --out "$results" >"$work/sweep.log" 2>&1 \
    || { tail -30 "$work/sweep.log" >&2; fail "testbed sweep failed (log: $work/sweep.log)"; }
[ -f "$results/results.json" ] || fail "the sweep wrote no results.json"

"$testbed" report "$results" >"$work/report.log" 2>&1 || { cat "$work/report.log" >&2; fail "testbed report failed"; }
page=$results/report.html
[ -f "$page" ] || fail "no $page"

# One run: --dump-dom prints the DOM once the page has loaded (after the load handlers ran),
# --screenshot captures the window.
flags=(--headless=new --no-sandbox --disable-gpu --hide-scrollbars --no-first-run
       --disable-extensions --enable-logging=stderr --v=0 --window-size=1400,3000
       --user-data-dir="$work/chromium-profile")
timeout 120 "$chromium" "${flags[@]}" --dump-dom --screenshot="$work/screenshot.png" "file://$page" \
    >"$work/dom.html" 2>"$work/chromium.log" \
    || { tail -20 "$work/chromium.log" >&2; fail "chromium failed (log: $work/chromium.log)"; }
[ -f "$work/screenshot.png" ] || fail "chromium wrote no screenshot"

# The element itself, not the script's text that mentions the same words.
status=$(grep -o '<pre id="page-check" data-status="[a-z]*">PAGE-CHECK: [A-Z]*' "$work/dom.html" | head -1 || true)
echo "report_chromium_test: ${status#*>}"
case "$status" in
    *'data-status="ok">PAGE-CHECK: OK') ;;
    "") fail "the page's check did not run (no #page-check in the DOM; see $work/dom.html)" ;;
    *) sed -n '/<pre id="page-check"/,/<\/pre>/p' "$work/dom.html" >&2; fail "the page reported problems" ;;
esac
# Console messages of the page (Chromium logs every console message and uncaught exception as a
# CONSOLE line; the report logs none); Chromium's own noise about D-Bus and the GPU in a
# container is not the page's and is not matched.
if grep -E 'CONSOLE|Uncaught|Failed to load resource|ERR_FILE_NOT_FOUND' "$work/chromium.log" >&2; then
    fail "the page logged errors (above; logs in $work)"
fi

"$python" - "$results" "$work/screenshot.png" "$work/dom.html" <<'EOF'
import json, os, sys
from html.parser import HTMLParser
import matplotlib.image as mpimg
import numpy as np
results, screenshot, dom = sys.argv[1], sys.argv[2], sys.argv[3]

class Page(HTMLParser):
    """The loaded page's groups (with their Pareto plots and thumbnails), the results table's
    header and the notes, as Chromium left them."""
    def __init__(self):
        super().__init__()
        self.groups = []          # [{"id", "pareto", "images"}]
        self.section_depth = 0
        self.depth = 0
        self.headers = []         # (data-column, class) of the results table
        self.in_results = False
        self.ids = set()
        self.table_attrs = {}
        self.families = []        # [{"id", "views", "aggregate_rows", "details_open", "view_rows"}]
        self.family_depth = 0
        self.table_class = None
    VOID = {"img", "br", "meta", "input", "link", "hr", "wbr", "source", "area", "col"}
    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag not in self.VOID:  # void elements have no end tag
            self.depth += 1
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "section" and "group" in (a.get("class") or "").split():
            self.groups.append({"id": a.get("data-group"), "pareto": 0, "images": 0})
            self.section_depth = self.depth
        if tag == "img" and self.section_depth:
            self.groups[-1]["images"] += 1
            if a.get("data-kind") == "pareto":
                self.groups[-1]["pareto"] += 1
        if tag == "section" and "view-family" in (a.get("class") or "").split():
            self.families.append({"id": a.get("data-family"), "views": a.get("data-views"),
                                  "aggregate_rows": 0, "details_open": None, "view_rows": 0})
            self.family_depth = self.depth
        if self.family_depth:
            if tag == "table":
                self.table_class = a.get("class")
            if tag == "details":
                self.families[-1]["details_open"] = "open" in a
            if tag == "tr" and a.get("data-method") is not None and self.table_class == "views-aggregate":
                self.families[-1]["aggregate_rows"] += 1
            if tag == "td" and self.table_class == "per-view-rows":
                self.families[-1]["view_rows"] += 1  # cells, divided below
        if tag == "table" and a.get("id") == "results-table":
            self.in_results = True
            self.table_attrs = a
        if tag == "th" and self.in_results:
            self.headers.append((a.get("data-column"), a.get("class") or ""))
    def handle_endtag(self, tag):
        if tag == "section" and self.section_depth == self.depth:
            self.section_depth = 0
        if tag == "section" and self.family_depth == self.depth:
            self.family_depth = 0
        if tag == "table":
            self.in_results = False
        self.depth -= 1

page = Page()
page.feed(open(dom, encoding="utf-8").read())
results_json = json.load(open(os.path.join(results, "results.json")))
ok_jobs = [j for j in results_json["jobs"] if j["status"] == "ok"]
problems = []
print("  groups on the page: %s" % page.groups)
if len(page.groups) != 4:
    problems.append("expected 4 comparable groups (16 and 64 lights x 2 views), found %d" % len(page.groups))
for group in page.groups:
    if group["pareto"] != 1:
        problems.append("group %s has %d Pareto plots, expected exactly 1" % (group["id"], group["pareto"]))
    if group["images"] < 1 + 4 * 3:  # the plot and preview, heatmap, error (+ flip) of 4 jobs
        problems.append("group %s shows only %d images" % (group["id"], group["images"]))
print("  view families on the page: %s" % page.families)
if len(page.families) != 2 or "views" not in page.ids:
    problems.append("expected an Across views section with 2 families (16 and 64 lights), found %d" % len(page.families))
for family in page.families:
    if family["views"] != "2":
        problems.append("family %s aggregates %s views, expected 2" % (family["id"], family["views"]))
    if family["aggregate_rows"] != 4:
        problems.append("family %s has %d aggregate rows, expected one per stage (4)" % (family["id"], family["aggregate_rows"]))
    if family["details_open"] is not False:
        problems.append("family %s: the per-view rows are not behind a closed toggle (%s)" % (family["id"], family["details_open"]))
    cells_per_row = 4 + 3  # method, view, group, job + time, error, FLIP
    if family["view_rows"] != 8 * cells_per_row:
        problems.append("family %s has %d per-view cells, expected 8 rows of %d" % (family["id"], family["view_rows"], cells_per_row))
columns = dict(page.headers)
if "flip" not in columns:
    problems.append("the results table has no flip (FLIP) column: %s" % list(columns))
elif "extra" in columns["flip"]:
    problems.append("the flip column is hidden behind the toggle; it is a main column")
main = (page.table_attrs.get("data-main-columns") or "").split()
for wanted in ("stage", "time_total_median_ms", "relative_rmse", "flip", "culling_efficiency"):
    if wanted not in main:
        problems.append("%s is not among the main columns %s" % (wanted, main))
if not any("extra" in cls for _, cls in page.headers):
    problems.append("no column is behind the toggle")
if "toggle-columns" not in page.ids:
    problems.append("no toggle button")
flip_missing = [j for j in ok_jobs if j.get("flip") is None]
if flip_missing and "flip-note" not in page.ids:
    problems.append("%d jobs lack FLIP but the page has no #flip-note" % len(flip_missing))
if not flip_missing and "flip-note" in page.ids:
    problems.append("every job has FLIP, yet the page says it is unavailable")
print("  FLIP: %s" % ("unavailable on %d jobs: %s" % (len(flip_missing), flip_missing[0].get("flip_unavailable"))
                      if flip_missing else "measured on every job"))
if "counts-note" not in page.ids:
    problems.append("inferred counts lights at reduced resolution but the page has no #counts-note")

def distinct_colours(path):
    pixels = mpimg.imread(path)
    if pixels.dtype != np.uint8:
        pixels = np.round(pixels * 255).astype(np.uint8)
    rgb = pixels[..., :3].reshape(-1, 3)
    background = np.all(rgb >= 250, axis=1)
    return len(np.unique(rgb, axis=0)), 1.0 - background.mean()

manifest = json.load(open(os.path.join(results, "report", "plots.json")))
if len(manifest["plots"]) < 4:
    problems.append("only %d plots drawn: %s" % (len(manifest["plots"]), manifest))
for plot in manifest["plots"]:
    colours, inked = distinct_colours(os.path.join(results, "report", plot["file"]))
    print("  plot %-32s %5d colours, %4.1f %% non-white" % (plot["file"], colours, 100 * inked))
    if colours < 32 or inked < 0.02:
        problems.append("plot %s looks blank (%d colours, %.3f non-white)" % (plot["file"], colours, inked))
colours, inked = distinct_colours(screenshot)
print("  screenshot %d colours, %.1f %% non-white" % (colours, 100 * inked))
if colours < 256 or inked < 0.05:
    problems.append("screenshot looks blank (%d colours)" % colours)
if problems:
    print("\n".join(problems), file=sys.stderr)
    sys.exit(1)
EOF
echo "report_chromium_test: PASS (page $page, screenshot $work/screenshot.png)"
