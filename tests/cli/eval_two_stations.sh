# The two bundled stations and the scene the P-wave and regional CLI tests run plinth-eval on
# (sourced after harness.sh, in its $TMP): LA - City Terrace (Rhyp 42.9 km: its P wave 5 s before
# the strong motion, a regional alert before the S waves) and Rinaldi (Rhyp 20.6 km: near the
# source, no P wave before the strong motion, a regional alert in the blind zone); the isolated
# block without its fragility (no-fragility.toml) and with one of this test's (isolated.toml).
PW=$SRC/sim/data/records/pwave
STATIONS=(--record "$PW/RSN990_NORTHR_LAC090.AT2" --vertical "$PW/RSN990_NORTHR_LAC-UP.AT2"
  --record "$PW/RSN1063_NORTHR_RRS228.AT2" --vertical "$PW/RSN1063_NORTHR_RRS-UP.AT2")
sed -e '/^\[fragility\]/,/^\[/{/^\[fragility\]/d;/^median_g/d;/^beta/d}' \
  "$SRC/sim/scenes/eval/isolated.toml" > no-fragility.toml
grep -q "median_g" no-fragility.toml && { echo "no-fragility.toml kept its fragility" >&2; exit 1; }
cp no-fragility.toml isolated.toml
printf '\n[fragility]\nmedian_g = 0.8\nbeta = 0.3\n' >> isolated.toml
GRID=(--scene isolated.toml "${STATIONS[@]}" --statues 2 --pga-from 0.4g --pga-to 1.6g
  --pga-steps 4)
