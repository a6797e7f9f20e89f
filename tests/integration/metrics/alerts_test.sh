#!/usr/bin/env bash
# The example alert rules load and fire as intended (promtool check/test rules), and every
# cosmic_* metric the rules and the Grafana dashboard use exists in docs/metrics.md.
#   alerts_test.sh PROMTOOL SOURCE_DIR
set -uo pipefail
PROMTOOL=$1 SRC=$2
[ -x "$PROMTOOL" ] || { echo "FAIL: $PROMTOOL: promtool is not installed (scripts/setup installs the prometheus package)" >&2; exit 1; }
FAILED=0
fail() { echo "FAIL: $*" >&2; FAILED=1; }

"$PROMTOOL" check rules "$SRC/dashboards/cosmicd-alerts.yml" || fail "promtool check rules"
(cd "$SRC/dashboards" && "$PROMTOOL" test rules cosmicd-alerts.test.yml) || fail "promtool test rules"

python3 - "$SRC" <<'PY' || FAILED=1
import json, re, sys
src = sys.argv[1]
docs = open(f"{src}/docs/metrics.md").read()
documented = set(re.findall(r"`(cosmic_[a-z0-9_]+)`", docs))
dashboard = json.load(open(f"{src}/dashboards/grafana-cosmicd.json"))
exprs = [t["expr"] for p in dashboard["panels"] for t in p.get("targets", [])]
exprs += [q["query"] for q in dashboard["templating"]["list"]]
rules = open(f"{src}/dashboards/cosmicd-alerts.yml").read()
used = set(re.findall(r"cosmic_[a-z0-9_]+", "\n".join(exprs) + rules))
# A histogram's series are documented under the family name.
missing = sorted(n for n in used if re.sub(r"_(bucket|count)$", "", n) not in documented)
if missing:
    print("FAIL: not in docs/metrics.md: " + ", ".join(missing), file=sys.stderr)
    sys.exit(1)
if len(exprs) < 10:
    print("FAIL: the dashboard has almost no queries", file=sys.stderr)
    sys.exit(1)
print(f"dashboard: {len(exprs)} queries, rules and dashboard use {len(used)} documented metrics")
PY
exit "$FAILED"
