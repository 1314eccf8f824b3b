#!/bin/sh
# Runs the Heitz 2016 supplement's listing timing (../shared/bench/heitz2016-listing/run.sh,
# g++ -O2) and the crate's `listing/` bench group (the same fixed directions) back to back, and
# prints listing ns / crate ns per configuration (the GGX dielectric's eval with omega_o inside,
# the listing's wo_sph=2.54 line, as `eval_inside`) and their geometric mean. Both sides measure
# wall time (the listing's driver uses steady_clock; set MICROSURFACE_BENCH_CLOCK=cpu to give
# criterion the thread's CPU time instead, which flatters the crate on a loaded machine);
# MEASUREMENT_TIME (seconds, default 2) sets criterion's measurement time.
# Usage: benches/compare-listing.sh [path/to/heitz2016-listing]
set -e
cd "$(dirname "$0")/.."
# default: the shared directory beside the main checkout (../shared) or beside a worktree of it
listing_dir=${1:-}
if [ -z "$listing_dir" ]; then
  for d in ../shared/bench/heitz2016-listing ../../shared/bench/heitz2016-listing; do
    if [ -x "$d/run.sh" ]; then listing_dir=$d; break; fi
  done
fi
[ -n "$listing_dir" ] || { echo "heitz2016-listing not found; pass its path" >&2; exit 2; }
out=${TMPDIR:-/tmp}/compare-listing.$$
"$listing_dir/run.sh" >"$out.listing"
cargo bench --bench walk -- '^listing/' \
  --measurement-time "${MEASUREMENT_TIME:-2}" --warm-up-time 0.5 2>/dev/null >"$out.crate"
awk '
  FNR == NR {
    if ($0 ~ /^material=/) {
      split($1, m, "="); split($2, s, "="); split($5, w, "[=,]"); split($6, e, "="); split($7, p, "=");
      if (w[2] + 0 > 1.5708) {
        # omega_o below the horizon (the dielectric transmission seen from inside); its sample
        # is the same call as the configuration above
        lst[m[2] "/" s[2] "/eval_inside"] = e[2]
      } else {
        lst[m[2] "/" s[2] "/eval"] = e[2]; lst[m[2] "/" s[2] "/sample"] = p[2]
      }
    }
    next
  }
  /^listing\// { id = $1; sub(/^listing\//, "", id) }
  /time:/ && id != "" {
    # time:   [low unit median unit high unit]
    t = substr($0, index($0, "[") + 1); split(t, f, " ")
    v = f[3]; u = f[4]; if (u == "µs") v *= 1000; else if (u == "ps") v /= 1000;
    crate[id] = v; order[++n] = id; id = ""
  }
  END {
    printf "%-30s %12s %12s %8s\n", "config (alpha 0.5, theta_i 0.5)", "listing ns", "crate ns", "ratio"
    for (k = 1; k <= n; k++) {
      c = order[k]; r = lst[c] / crate[c]; log_sum += log(r); if (k == 1 || r < low) low = r
      printf "%-30s %12.1f %12.1f %7.2fx\n", c, lst[c], crate[c], r
    }
    if (n > 0) printf "%-30s %12s %12s %7.2fx (lowest %.2fx, %d configurations)\n", "geometric mean", "", "", exp(log_sum / n), low, n
  }' "$out.listing" "$out.crate"
rm -f "$out.listing" "$out.crate"
