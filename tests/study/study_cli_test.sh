#!/usr/bin/env bash
# End-to-end checks of `lamina study` and `lamina compare` on a tiny budget: outputs, resuming
# after a kill, a corrupt cache, bad arguments. Usage: study_cli_test.sh LAMINA SRC_DIR
set -u
lamina=$1
src=$2
. "$(dirname "$0")/../support/script_lib.sh"

tiny=(--only 'plastic-P1-a0.05,slab-a0.1-a1.3-clear' --models ww-prime,bel-prime
      --theta-i 0,60 --particles 4e4 --grid 18x18)

# 1. A tiny study runs end to end and writes the documented files.
if "$lamina" study "${tiny[@]}" --out "$tmp/a" >"$tmp/a.log" 2>&1; then ok; else fail "study run"; cat "$tmp/a.log"; fi
for f in study.json metrics.csv summary.md summary.json \
         configs/plastic-P1-a0.05/config.json configs/plastic-P1-a0.05/tables.lza \
         configs/plastic-P1-a0.05/reference_se.lza configs/slab-a0.1-a1.3-clear/tables.lza; do
    [ -s "$tmp/a/$f" ] && ok || fail "missing $f"
done
head -1 "$tmp/a/metrics.csv" | grep -qx \
    'config,category,model,theta_i,side,channel,misplaced_energy,misplaced_floor,albedo_ref,albedo_model,albedo_error,rmse,log_rmse,noise_floor,misplaced_floor_noise,supported' \
    && ok || fail "metrics.csv header"
# plastic: 2 models × 2 incidences × R × 3 channels; slab: 2 × 2 × (R, T) × 3; plus the header.
[ "$(wc -l <"$tmp/a/metrics.csv")" -eq 37 ] && ok || fail "metrics.csv rows: $(wc -l <"$tmp/a/metrics.csv")"
# bel-prime has no Lambertian base: its plastic rows are 'not supported' with empty metrics.
grep -q '^plastic-P1-a0.05,plastic,bel-prime,0,R,r,,,,,,,,,,false$' "$tmp/a/metrics.csv" \
    && ok || fail "unsupported rows"
grep -q '^slab-a0.1-a1.3-clear,slab,bel-prime,60,T,b,[0-9]' "$tmp/a/metrics.csv" \
    && ok || fail "bel-prime BTDF rows"
grep -q '^## Findings' "$tmp/a/summary.md" && ok || fail "summary findings"
grep -q '^## Approximations assessment' "$tmp/a/summary.md" && ok || fail "summary assessment"
grep -q 'Findings' "$tmp/a.log" && ok || fail "findings printed"
grep -Eq '^Time \(wall / CPU s\): reference [0-9.]+ / [0-9.]+, model tables [0-9.]+ / [0-9.]+,.*; slowest tables: (ww-prime|bel-prime) [0-9.]+ / [0-9.]+, (ww-prime|bel-prime) ' "$tmp/a.log" \
    && ok || { fail "where the time went:"; grep Time "$tmp/a.log"; }

# 2. Re-running a finished study does no work and rewrites nothing: the counts it reports are 0
#    and every file keeps its modification time (and content).
snapshot() { (cd "$1" && find . -type f -printf '%P %s %T@\n' | sort); }
snapshot "$tmp/a" >"$tmp/a.before"
cp "$tmp/a/metrics.csv" "$tmp/a.metrics"
"$lamina" study "${tiny[@]}" --out "$tmp/a" >"$tmp/a2.log" 2>&1 && ok || fail "rerun"
grep -qF 'Work: 0 reference pieces simulated, 0 model tables computed (4 reused), 0 configurations written (2 unchanged), 0 summary files written' "$tmp/a2.log" \
    && ok || { fail "rerun did work:"; grep Work "$tmp/a2.log"; }
grep -q 'figures: 0 drawn' "$tmp/a2.log" && ok || { fail "rerun redrew figures:"; grep figures: "$tmp/a2.log"; }
snapshot "$tmp/a" >"$tmp/a.after"
diff "$tmp/a.before" "$tmp/a.after" >"$tmp/a.diff" && ok || { fail "rerun rewrote files:"; cat "$tmp/a.diff"; }
grep -q 'Findings' "$tmp/a2.log" && ok || fail "findings printed on a rerun"
# A truncated explorer data file is encoded again, not trusted from the stamps.
rm -rf "$tmp/a-js" && cp -r "$tmp/a" "$tmp/a-js"
js=$(find "$tmp/a-js/explorer/data" -name 'plastic-*.js' | head -1)
cp "$js" "$tmp/a-js.saved" && truncate -s 100 "$js"
"$lamina" explorer "$tmp/a-js" >/dev/null 2>&1 && cmp -s "$js" "$tmp/a-js.saved" && ok \
    || fail "a truncated explorer data file was kept"

# 2b. Adding a model computes that model's tables only (no reference piece, nothing for the
#     others), and gives bitwise the metrics and tables of a fresh study with the three models.
three=(--only 'plastic-P1-a0.05,slab-a0.1-a1.3-clear' --models ww-prime,bel-prime,ww09
       --theta-i 0,60 --particles 4e4 --grid 18x18)
"$lamina" study "${three[@]}" --out "$tmp/a" >"$tmp/a3.log" 2>&1 && ok || fail "add a model"
grep -qF 'Work: 0 reference pieces simulated, 2 model tables computed (4 reused), 2 configurations written' "$tmp/a3.log" \
    && ok || { fail "adding a model:"; grep Work "$tmp/a3.log"; }
"$lamina" study "${three[@]}" --no-figures --out "$tmp/f" >/dev/null 2>&1 && ok || fail "fresh three-model study"
for f in metrics.csv summary.json configs/plastic-P1-a0.05/tables.lza configs/slab-a0.1-a1.3-clear/tables.lza \
         configs/slab-a0.1-a1.3-clear/config.json configs/slab-a0.1-a1.3-clear/reference_se.lza; do
    cmp -s "$tmp/a/$f" "$tmp/f/$f" && ok || fail "incremental $f differs from a fresh study's"
done
# Back to two models: nothing is computed, and the metrics are those of the first run.
"$lamina" study "${tiny[@]}" --out "$tmp/a" >"$tmp/a4.log" 2>&1
grep -qF ' 0 model tables computed (4 reused)' "$tmp/a4.log" && ok || { fail "back to two models:"; grep Work "$tmp/a4.log"; }
cmp -s "$tmp/a/metrics.csv" "$tmp/a.metrics" && ok || fail "metrics after going back to two models"

# 2c. Adding a configuration simulates and computes only that configuration; the other one is
#     read back unchanged.
"$lamina" study --only 'plastic-P1-a0.05' --models ww-prime,bel-prime --theta-i 0,60 --particles 4e4 \
    --grid 18x18 --no-figures --out "$tmp/g" >/dev/null 2>&1 && ok || fail "one configuration"
"$lamina" study "${tiny[@]}" --no-figures --out "$tmp/g" >"$tmp/g.log" 2>&1 && ok || fail "add a configuration"
grep -qF 'Work: 2 reference pieces simulated, 2 model tables computed (2 reused), 1 configurations written (1 unchanged)' "$tmp/g.log" \
    && ok || { fail "adding a configuration:"; grep Work "$tmp/g.log"; }
cmp -s "$tmp/g/metrics.csv" "$tmp/a.metrics" && ok || fail "metrics after adding a configuration"

# 2d. Table formats: half (the default) is float16, full float32, none writes no tables (and the
#     metrics do not depend on it); the Ω⊥ of the figure script agrees with lamina's (the albedo
#     it computes from the float32 tables is metrics.csv's albedo_ref).
"$lamina" study "${tiny[@]}" --tables full --no-figures --out "$tmp/full" >/dev/null 2>&1 && ok || fail "--tables full"
"$lamina" study "${tiny[@]}" --tables none --no-figures --out "$tmp/none" >/dev/null 2>&1 && ok || fail "--tables none"
cmp -s "$tmp/full/metrics.csv" "$tmp/a.metrics" && ok || fail "metrics depend on --tables"
cmp -s "$tmp/none/metrics.csv" "$tmp/a.metrics" && ok || fail "metrics depend on --tables none"
[ ! -e "$tmp/none/configs/plastic-P1-a0.05/tables.lza" ] && ok || fail "--tables none wrote tables"
[ -z "$(find "$tmp/a/configs" -name '*.npy')" ] && ok || fail "a study wrote .npy tables"
# Debian's interpreter, the one with numpy and matplotlib (as `lamina figures` chooses it).
py=python3
[ -x /usr/bin/python3 ] && py=/usr/bin/python3
"$py" - "$tmp" "$src/scripts/figures.py" <<'PY' && ok || fail "table formats / Ω⊥"
import csv, importlib.util, json, sys
import numpy as np
tmp, script = sys.argv[1], sys.argv[2]
spec = importlib.util.spec_from_file_location("figures", script)
figures = importlib.util.module_from_spec(spec)
spec.loader.exec_module(figures)
cid = "slab-a0.1-a1.3-clear"
half = figures.read_array(f"{tmp}/a/configs/{cid}/tables.lza")
full = figures.read_array(f"{tmp}/full/configs/{cid}/tables.lza")
assert half.dtype == np.float16 and full.dtype == np.float32, (half.dtype, full.dtype)
assert json.load(open(f"{tmp}/a/configs/{cid}/config.json"))["tables"]["dtype"] == "float16"
ok = np.isfinite(full)
assert np.array_equal(np.isnan(half), np.isnan(full))
assert np.allclose(half[ok], full[ok], rtol=2 ** -11, atol=6e-8), "half is not full rounded"
om = figures.omega_perp(18, 18)
theta_i = json.load(open(f"{tmp}/full/study.json"))["theta_i"]
n = 0
for r in csv.DictReader(open(f"{tmp}/full/metrics.csv")):
    if r["config"] != cid or r["supported"] != "true":
        continue
    i, d, c = theta_i.index(float(r["theta_i"])), "RT".index(r["side"]), "rgb".index(r["channel"])
    albedo = float((full[0, i, d, :, :, c].astype(np.float64) * om).sum())
    assert abs(albedo - float(r["albedo_ref"])) <= 1e-6 * float(r["albedo_ref"]), (r, albedo)
    n += 1
assert n >= 6, n
PY

# 2e. A study written before packed arrays (configs/<id>/*.npy) is read and upgraded: the models
#     are reused from its .npy tables, which give way to .lza files equal to a fresh study's.
cp -r "$tmp/a" "$tmp/old"
"$py" - "$tmp/old" "$src/src/python/lamina/arrays.py" <<'PY' && ok || fail "writing an old-style study"
import glob, importlib.util, os, sys
import numpy as np
spec = importlib.util.spec_from_file_location("arrays", sys.argv[2])
arrays = importlib.util.module_from_spec(spec)
spec.loader.exec_module(arrays)
for f in glob.glob(f"{sys.argv[1]}/configs/*/*.lza"):
    np.save(f[:-4] + ".npy", arrays.read_array(f))
    os.remove(f)
PY
"$lamina" study "${tiny[@]}" --no-figures --out "$tmp/old" >"$tmp/old.log" 2>&1 && ok || fail "upgrade run"
grep -qF 'Work: 0 reference pieces simulated, 0 model tables computed (4 reused), 2 configurations written' "$tmp/old.log" \
    && ok || { fail "upgrading an old study:"; grep Work "$tmp/old.log"; }
[ -z "$(find "$tmp/old/configs" -name '*.npy')" ] && ok || fail "the .npy tables stayed"
for f in configs/plastic-P1-a0.05/tables.lza configs/slab-a0.1-a1.3-clear/reference_se.lza; do
    cmp -s "$tmp/a/$f" "$tmp/old/$f" && ok || fail "upgraded $f differs"
done

# 2f. `lamina export --study` reads the packed tables: its .npz holds the study's float32 table.
"$lamina" export --study "$tmp/full" --config slab-a0.1-a1.3-clear --source bel-prime \
    --out "$tmp/bel.npz" >/dev/null 2>&1 && ok || fail "export --study"
"$py" - "$tmp" "$src/src/python/lamina/arrays.py" <<'PY' && ok || fail "export --study's table"
import importlib.util, json, sys
import numpy as np
spec = importlib.util.spec_from_file_location("arrays", sys.argv[2])
arrays = importlib.util.module_from_spec(spec)
spec.loader.exec_module(arrays)
d = f"{sys.argv[1]}/full/configs/slab-a0.1-a1.3-clear"
t = arrays.read_array(f"{d}/tables.lza")
k = json.load(open(f"{d}/config.json"))["sources"].index("bel-prime")
f = np.load(f"{sys.argv[1]}/bel.npz")["f"]
assert f.shape == t[k].shape and np.array_equal(f, t[k]), (f.shape, t[k].shape)
PY

# 2g. A damaged study folder is refused by name, never read without bound or passed on: a grid
#     out of range (it sized arrays: a crash), a table file that is a device (read without end),
#     a NaN or negative standard error (copied into the .npz), a table of the wrong shape (Python).
LAMINA="$lamina" LAMINA_PYTHONPATH="$(dirname "$lamina")/python" \
    "$py" - "$tmp" "$src/src/python/lamina/arrays.py" <<'PY' && ok || fail "damaged study folders"
import importlib.util, json, os, shutil, subprocess, sys, zlib
import numpy as np
spec = importlib.util.spec_from_file_location("arrays", sys.argv[2])
arrays = importlib.util.module_from_spec(spec)
spec.loader.exec_module(arrays)
tmp, lamina = sys.argv[1], os.environ["LAMINA"]
cfg = "slab-a0.1-a1.3-clear"

def damaged(tag, change):
    d = f"{tmp}/damaged-{tag}"
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(f"{tmp}/full", d, symlinks=True)
    change(d)
    return d

def refused(d, text, *commands):
    for args in commands:
        r = subprocess.run([lamina, *args(d)], capture_output=True, text=True)
        assert r.returncode == 1 and text in r.stderr, (args(d), r.returncode, r.stdout, r.stderr)

export = lambda d: ["export", "--study", d, "--config", cfg, "--out", d + ".npz"]
explorer = lambda d: ["explorer", d]

def set_grid(d):
    info = json.load(open(f"{d}/study.json"))
    info["grid"]["n_theta"] = -9
    json.dump(info, open(f"{d}/study.json", "w"))
refused(damaged("grid", set_grid), "/grid: -9 × ", export, explorer)

def study_field(key, value):  # the page drew nothing from these (the explorer's JavaScript failed)
    def change(d):
        info = json.load(open(f"{d}/study.json"))
        info[key] = value
        json.dump(info, open(f"{d}/study.json", "w"))
    return change
refused(damaged("theta", study_field("theta_i", [0, 1e308])),
        "/theta_i: 1e+308 is outside the allowed range [0, 90) degrees", explorer)
refused(damaged("models", study_field("models", ["lamina-1", 3])), "models", explorer)

def device(d):
    os.remove(f"{d}/configs/{cfg}/reference_se.lza")
    os.symlink("/dev/zero", f"{d}/configs/{cfg}/reference_se.lza")
refused(damaged("device", device), "not a regular file", export, explorer)

def write_lza(path, a):  # the packed format of docs/formats.md, float32
    data = open(path, "rb").read()
    eol = data.index(b"\n", len(b"lamina-array 1\n"))
    header = json.loads(data[len(b"lamina-array 1\n"):eol])
    n, c = a.shape[-2:]
    bits = np.ascontiguousarray(a.astype(np.float32)).view(np.uint32).reshape(-1, n, c)
    bits = np.ascontiguousarray(bits.swapaxes(-1, -2))
    diff = bits.copy()
    diff[..., 1:] = bits[..., 1:] - bits[..., :-1]
    flat = diff.reshape(-1)
    planes = np.stack([((flat >> np.uint32(8 * k)) & np.uint32(0xFF)).astype(np.uint8)
                       for k in range(4)])
    open(path, "wb").write(b"lamina-array 1\n" + json.dumps(header).encode() + b"\n" +
                           zlib.compress(planes.tobytes()))

for value, text in ((np.nan, "is nan: allowed finite, ≥ 0"), (-1.0, "is -1: allowed finite, ≥ 0")):
    def bad_se(d, value=value):
        p = f"{d}/configs/{cfg}/reference_se.lza"
        se = arrays.read_array(p).astype(np.float32)
        se[0, 0, 3, 3, 1] = value
        write_lza(p, se)
        assert arrays.read_array(p)[0, 0, 3, 3, 1] == value or np.isnan(value)
    refused(damaged("se", bad_se), text, export)

package = f"{os.environ['LAMINA_PYTHONPATH']}/lamina"
if not os.path.isdir(package) or not any(n.startswith("_lamina") for n in os.listdir(package)):
    sys.exit(0)  # built without the Python module: the CLI's part above is the test
def null_category(d):
    info = json.load(open(f"{d}/study.json"))
    info["configurations"][0]["category"] = None
    json.dump(info, open(f"{d}/study.json", "w"))
refused(damaged("category", null_category), "holds a value of the wrong type", explorer)

def no_sources(d):
    c = json.load(open(f"{d}/configs/{cfg}/config.json"))
    del c["sources"]
    json.dump(c, open(f"{d}/configs/{cfg}/config.json", "w"))
refused(damaged("sources", no_sources), "not lamina's configuration: key 'sources'", export)

def metric_not_a_number(d):
    lines = open(f"{d}/metrics.csv").read().splitlines()
    header = lines[0].split(",")
    cells = lines[1].split(",")
    cells[header.index("misplaced_floor")] = "x"
    lines[1] = ",".join(cells)
    open(f"{d}/metrics.csv", "w").write("\n".join(lines) + "\n")
refused(damaged("metric", metric_not_a_number), "row 2, misplaced_floor: 'x' is not a finite",
        explorer)
# Finite but beyond any metric the study writes (the page's sums overflowed), or a negative
# misplaced energy: refused by row and column.
for text, bound in (("1e308", "[0, 1e12]"), ("-1", "[0, 1e12]")):
    def metric_out_of_range(d, text=text):
        lines = open(f"{d}/metrics.csv").read().splitlines()
        header = lines[0].split(",")
        cells = lines[1].split(",")
        cells[header.index("misplaced_floor")] = text
        lines[1] = ",".join(cells)
        open(f"{d}/metrics.csv", "w").write("\n".join(lines) + "\n")
    refused(damaged("metric-range", metric_out_of_range),
            f"row 2, misplaced_floor: {text} is outside {bound}", explorer)

sys.path.insert(0, os.environ["LAMINA_PYTHONPATH"])
import lamina as lam
def one_incidence_less(d):
    c = json.load(open(f"{d}/configs/{cfg}/config.json"))
    c["theta_i"] = c["theta_i"][:-1]
    json.dump(c, open(f"{d}/configs/{cfg}/config.json", "w"))
st = lam.load_study(damaged("shape", one_incidence_less), pandas=False)
for read in (st.tables, st.reference_se):
    try:
        read(cfg)
        raise AssertionError(f"{read.__name__} accepted a table of the wrong shape")
    except lam.InputError as e:
        assert e.field == "shape" and "does not match config.json and study.json" in e.problem
# Every column of metrics.csv, the ranking's misplaced_floor included.
st = lam.load_study(f"{tmp}/full", pandas=False)
header = open(f"{tmp}/full/metrics.csv").readline().strip().split(",")
assert list(st.metrics.dtype.names) == header, (st.metrics.dtype.names, header)
# A metrics cell that is not a finite number is refused, as explorer refuses it.
for text in ("x", "inf", "nan"):
    def bad_metric(d, text=text):
        lines = open(f"{d}/metrics.csv").read().splitlines()
        cells = lines[1].split(",")
        cells[header.index("misplaced_floor")] = text
        lines[1] = ",".join(cells)
        open(f"{d}/metrics.csv", "w").write("\n".join(lines) + "\n")
    try:
        lam.load_study(damaged("py-metric", bad_metric), pandas=False)
        raise AssertionError(f"load_study accepted a metric {text!r}")
    except lam.InputError as e:
        assert "not lamina's metrics table" in e.problem, e
PY

# 2h. The incremental state read back is checked: a row edited out of range (1e308, which gave
#     "-inf%" in the summary) or negative, a row moved to another incidence or side, a model's
#     rows cut short, a loss of 1e308 or another format's state are recomputed, not reused.
for damage in huge negative moved side short loss format; do
    rm -rf "$tmp/state-$damage" && cp -r "$tmp/a" "$tmp/state-$damage"
    "$py" - "$tmp/state-$damage" "$damage" <<'PY'
import glob, json, sys
for path in glob.glob(f"{sys.argv[1]}/cache/study/*.json"):
    state = json.load(open(path))
    damage = sys.argv[2]
    if damage == "loss":
        state["lost_microsurface"][0][0] = 1e308
    elif damage == "format":
        state["format"] = "lamina-study-state v9"
    for model in state["models"].values():
        if damage == "huge":
            model["rows"][0][4] = 1e308
        elif damage == "negative":
            model["rows"][0][4] = -1.0
        elif damage == "moved":
            model["rows"][0][0] = 33.0
        elif damage == "side":
            model["rows"][0][1] = "T" if model["rows"][0][1] == "R" else "R"
        elif damage == "short":
            del model["rows"][1:]
    json.dump(state, open(path, "w"))
PY
    "$lamina" study "${tiny[@]}" --out "$tmp/state-$damage" >"$tmp/state-$damage.log" 2>&1 \
        && cmp -s "$tmp/state-$damage/metrics.csv" "$tmp/a.metrics" \
        && ! grep -q "inf%" "$tmp/state-$damage/summary.md" && ok \
        || { fail "a damaged state ($damage) was trusted"; cat "$tmp/state-$damage.log"; }
done

# 3. Killed part-way (kill -9 as soon as the first piece is stored), then resumed: the same
#    metrics.csv as the uninterrupted run.
"$lamina" study "${tiny[@]}" --out "$tmp/b" >/dev/null 2>&1 &
pid=$!
for _ in $(seq 1 3000); do
    if [ -n "$(find "$tmp/b/cache" -name '*.bin' 2>/dev/null | head -1)" ]; then break; fi
    sleep 0.01
done
kill -9 "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
pieces=$(find "$tmp/b/cache" -name '*.bin' 2>/dev/null | wc -l)
if [ "$pieces" -ge 1 ] && [ ! -e "$tmp/b/metrics.csv" ]; then ok; else fail "kill: $pieces pieces, metrics present: $([ -e "$tmp/b/metrics.csv" ] && echo yes)"; fi
[ -z "$(find "$tmp/b" -name '*.tmp-*')" ] || echo "note: a killed write left a temporary file (ignored by readers)"
"$lamina" study "${tiny[@]}" --out "$tmp/b" >/dev/null 2>&1 && ok || fail "resume"
cmp -s "$tmp/a/metrics.csv" "$tmp/b/metrics.csv" && ok || fail "resumed metrics differ"

# 4. A corrupt piece is recomputed, not trusted.
piece=$(find "$tmp/b/cache" -name '*.bin' | head -1)
printf 'garbage' >"$piece"
"$lamina" study "${tiny[@]}" --out "$tmp/b" >/dev/null 2>&1 && ok || fail "corrupt rerun"
cmp -s "$tmp/a/metrics.csv" "$tmp/b/metrics.csv" && ok || fail "metrics after corrupt piece"

# 5. compare on one stack file.
"$lamina" compare "$src/examples/metallic-paint.json" --theta-i 30 --particles 2e4 --grid 18x18 \
    --models ww-prime,bel18-symmetric --out "$tmp/c" >/dev/null 2>&1 && ok || fail "compare"
[ -s "$tmp/c/configs/metallic-paint/tables.lza" ] && ok || fail "compare tables"
[ "$(wc -l <"$tmp/c/metrics.csv")" -eq 7 ] && ok || fail "compare rows"

# 6. Bad arguments: a clear message and a non-zero exit.
expect_error() {  # expect_error TEXT ARGS...
    local text=$1
    shift
    if "$lamina" "$@" >"$tmp/err" 2>&1; then fail "accepted: $*"; return; fi
    grep -qF -- "$text" "$tmp/err" && ok || { fail "message for $*:"; cat "$tmp/err"; }
}
expect_error "--preset: 'huge' is not a preset" study --preset huge --out "$tmp/x"
expect_error "--only: 'nothing' matches no configuration" study --only nothing --out "$tmp/x"
# Given empty, --only names nothing: not every configuration (a whole study) by accident.
expect_error "--only: '' names no configuration" study --only '' --out "$tmp/x"
expect_error "--only: ', ' names no configuration" figures "$tmp/x" --only ', '
expect_error "unknown model" study --models ww-prime,nope --only 'plastic-P1-a0.05' --out "$tmp/x"
expect_error "--theta-i: 95 is outside" study --theta-i 95 --out "$tmp/x"
echo '{"configurations": [{"id": "a b", "stack": {}}]}' >"$tmp/bad.json"
expect_error "/configurations/0/id" study --configs "$tmp/bad.json" --out "$tmp/x"

expect_error "--microsurface: 'double' is not a microsurface model" \
    study --microsurface double --kernel scalar --only 'plastic-P1-a0.05' --out "$tmp/x"

expect_error "--transmission-masking: 'walter' is not a transmission masking" \
    study --transmission-masking walter --only 'plastic-P1-a0.05' --out "$tmp/x"

# 7. The 2019 reference (--physics bpb19) and the same with multiple scattering: each its own
#    cache pieces (the key says so), nothing lost to the microsurfaces in the budgets of the
#    second, and study.json and summary.json say which reference it is.
ms=(--only 'plastic-P1-a0.05' --models ww-prime --theta-i 60 --particles 2e4 --grid 18x18
    --no-figures --physics bpb19)
"$lamina" study "${ms[@]}" --out "$tmp/m" >/dev/null 2>&1 && ok || fail "single-scattering study"
python3 -c "import json,sys; assert json.load(open(sys.argv[1]))['physics'] == 'bpb19'" \
    "$tmp/m/study.json" && ok || fail "study.json physics bpb19"
"$lamina" study "${ms[@]}" --microsurface multiple --out "$tmp/m" >/dev/null 2>&1 \
    && ok || fail "multiple-scattering study"
[ "$(find "$tmp/m/cache" -name '*.bin' | wc -l)" -eq 2 ] && ok || fail "one cache piece per model"
python3 - "$tmp/m" <<'PY' && ok || fail "multiple-scattering outputs"
import json, sys
d = sys.argv[1]
assert json.load(open(d + "/study.json"))["microsurface"] == "multiple"
assert json.load(open(d + "/study.json"))["physics"] == "custom"
assert json.load(open(d + "/summary.json"))["microsurface"] == "multiple"
for e in json.load(open(d + "/configs/plastic-P1-a0.05/config.json"))["energy"]:
    assert e["lost_microsurface"] == [0, 0, 0], e
PY

# 8. Production coats and their ablations: NAME:KEY=VALUE in --models, --ablations adds each
#    one-flag variant; study.json names their groups; the summary has the engine developers'
#    section with the ablation's row.
ab=(--only 'plastic-P1-a0.05' --models ww-prime,gltf-clearcoat,openpbr:darkening=off
    --theta-i 60 --particles 2e4 --grid 18x18 --no-figures)
"$lamina" study "${ab[@]}" --ablations --out "$tmp/p" >/dev/null 2>&1 && ok || fail "ablation study"
python3 - "$tmp/p" <<'PY' && ok || fail "ablation outputs"
import json, sys
d = sys.argv[1]
s = json.load(open(d + "/study.json"))
assert s["models"] == ["ww-prime", "gltf-clearcoat", "openpbr:darkening=off",
                       "gltf-clearcoat:coat-fresnel=h", "gltf-clearcoat:leaves=exact"], s["models"]
assert s["model_groups"] == {"ww-prime": "2019", "gltf-clearcoat": "production",
                             "openpbr:darkening=off": "ablations",
                             "gltf-clearcoat:coat-fresnel=h": "ablations",
                             "gltf-clearcoat:leaves=exact": "ablations"}, s["model_groups"]
e = json.load(open(d + "/summary.json"))["engine_developers"]["categories"]["plastic"]
assert e["most_accurate_production"] == "gltf-clearcoat", e
assert [a["flag"] for a in e["ablations"]] == ["coat-fresnel=h", "leaves=exact"], e["ablations"]
PY
grep -q '^## For engine developers' "$tmp/p/summary.md" && ok || fail "engine developers section"
expect_error "model 'openpbr' has no option 'tint'" study --models openpbr:tint=off \
    --only 'plastic-P1-a0.05' --out "$tmp/x"
# 9. The refraction masking: a pbrt reference of a rough-coated configuration is a cache piece of
#    its own (a cache made before the option, with that form, stays valid for it; one made with
#    the Smith form is never reused as pbrt), and study.json says which.
"$lamina" study "${ms[@]}" --transmission-masking pbrt --out "$tmp/m" >/dev/null 2>&1 \
    && ok || fail "pbrt-masking study"
[ "$(find "$tmp/m/cache" -name '*.bin' | wc -l)" -eq 3 ] && ok || fail "one cache piece per masking"
python3 -c "import json,sys; assert json.load(open(sys.argv[1]))['transmission_masking'] == 'pbrt'" \
    "$tmp/m/study.json" && ok || fail "study.json transmission_masking"
# 10. --phi-i lights an isotropic configuration from that azimuth: unfolded, its pieces keyed by φi,
#     metrics.csv with its phi_i column, config.json with the grid and the incidences.
"$lamina" study --only 'paint-a0.05-a1.3' --models openpbr --theta-i 0,45 --phi-i 30 \
    --particles 2e4 --grid 18x18 --no-figures --out "$tmp/phi" >/dev/null 2>&1 && ok || fail "--phi-i study"
[ "$(find "$tmp/phi/cache" -name 'theta45-phi30-*.bin' | wc -l)" -eq 1 ] && ok || fail "--phi-i piece name"
grep -q '^paint-a0.05-a1.3,metallic-paint,openpbr,45,30,R,g,[0-9]' "$tmp/phi/metrics.csv" \
    && ok || fail "--phi-i metrics.csv rows"
python3 -c "import json,sys; c = json.load(open(sys.argv[1])); \
assert c['grid'] == '18x18 unfolded' and c['phi_i'] == [30, 30] and c['tables']['shape'][4] == 36" \
    "$tmp/phi/configs/paint-a0.05-a1.3/config.json" && ok || fail "--phi-i config.json"
# 10b. export --study of an unfolded configuration: its .npz holds every incidence (θi, φi) of the
#      study, values and standard errors bit for bit; a .bsdf of its reference, which holds the
#      light at φi = 30° only, is refused with what to do; a model's .bsdf evaluates the model.
if "$lamina" export --study "$tmp/phi" --config paint-a0.05-a1.3 --out "$tmp/phi.bsdf" >"$tmp/phi-export" 2>&1; then
    fail "export of an unfolded configuration's reference as .bsdf accepted"
else
    grep -q "config.json: --source: 'paint-a0.05-a1.3' is compared on the unfolded grid (18x18 unfolded), its light from φi = 30° only" "$tmp/phi-export" \
        && grep -q "write the reference as .npz" "$tmp/phi-export" \
        && ok || { fail "export message:"; cat "$tmp/phi-export"; }
fi
[ ! -e "$tmp/phi.bsdf" ] && ok || fail "a refused export wrote a file"
"$lamina" export --study "$tmp/phi" --config paint-a0.05-a1.3 --out "$tmp/phi.npz" >/dev/null 2>&1 \
    && ok || fail "export --study of an unfolded configuration as .npz"
# A study's unfolded tables against the .npz: the same values (float16 → float32 exactly).
check_unfolded_npz() {  # STUDY CONFIG SOURCE NPZ
    "$py" - "$@" "$src/src/python/lamina/arrays.py" <<'PY'
import importlib.util, json, sys, zipfile
import numpy as np
study, cid, source, npz, arrays_py = sys.argv[1:6]
spec = importlib.util.spec_from_file_location("arrays", arrays_py)
arrays = importlib.util.module_from_spec(spec)
spec.loader.exec_module(arrays)
d = f"{study}/configs/{cid}"
cfg = json.load(open(f"{d}/config.json"))
t = arrays.read_array(f"{d}/tables.lza")[cfg["sources"].index(source)].astype(np.float32)
z = np.load(npz)
assert z["f"].shape == t.shape and np.array_equal(z["f"], t), (z["f"].shape, t.shape)
assert list(z["theta_i"]) == cfg["theta_i"] and list(z["phi_i"]) == cfg["phi_i"]
assert z["phi_edges"][-1] == 360 and len(z["phi_edges"]) == t.shape[3] + 1
se = arrays.read_array(f"{d}/reference_se.lza").astype(np.float32)
assert np.array_equal(z["se"], se if source == "reference" else np.zeros_like(se))
meta = json.loads(zipfile.ZipFile(npz).read("metadata.json"))
assert meta["grid"]["unfolded"] is True and meta["theta_i"] == cfg["theta_i"]
PY
}
check_unfolded_npz "$tmp/phi" paint-a0.05-a1.3 reference "$tmp/phi.npz" && ok || fail "unfolded .npz"
"$lamina" export --study "$tmp/phi" --config paint-a0.05-a1.3 --source openpbr --theta-i 0,30,60 \
    --resolution 24 --out "$tmp/phi-openpbr.bsdf" >/dev/null 2>&1 && ok || fail "a model's .bsdf of an unfolded configuration"
"$lamina" export --check "$tmp/phi-openpbr.bsdf" --study "$tmp/phi" --config paint-a0.05-a1.3 \
    --source openpbr >"$tmp/phi-check" 2>&1 && grep -q 'against its source, openpbr' "$tmp/phi-check" \
    && ok || { fail "--check against an unfolded configuration's model"; cat "$tmp/phi-check"; }

# 11. The brushed category (anisotropic: unfolded, lit from φi = 0°, 45°, 90°) through export.
"$lamina" study --preset standard --only 'brushed-al-a0.2-a1.05x.3' --models wb20 --theta-i 0,45 \
    --particles 2e4 --grid 9x12 --tables full --no-figures --out "$tmp/br" >/dev/null 2>&1 \
    && ok || fail "brushed study"
"$lamina" export --study "$tmp/br" --config brushed-al-a0.2-a1.05x.3 --out "$tmp/br.npz" >/dev/null 2>&1 \
    && check_unfolded_npz "$tmp/br" brushed-al-a0.2-a1.05x.3 reference "$tmp/br.npz" \
    && ok || fail "brushed .npz"
"$lamina" export --study "$tmp/br" --config brushed-al-a0.2-a1.05x.3 --source wb20 --out "$tmp/br-wb20.npz" >/dev/null 2>&1 \
    && check_unfolded_npz "$tmp/br" brushed-al-a0.2-a1.05x.3 wb20 "$tmp/br-wb20.npz" \
    && ok || fail "brushed model .npz"
# wb20's .bsdf: anisotropic (φi slices); read back by lamina's reader (--check), its albedo at the
# study's incidences (θi = 45° at φi = 0°, 45°, 90°: slice and incidence nodes of the file) is the
# study's table's, Σ f Ω⊥, within the 2 % goal of a file's albedo (docs/formats.md).
"$lamina" export --study "$tmp/br" --config brushed-al-a0.2-a1.05x.3 --source wb20 --azimuths 8 \
    --theta-i 0,15,30,45,60,75 --out "$tmp/br.bsdf" >"$tmp/br-export" 2>&1 \
    && ok || { fail "brushed model .bsdf"; cat "$tmp/br-export"; }
"$lamina" export --check "$tmp/br.bsdf" >"$tmp/br-desc" 2>&1 && grep -q '6 incidences' "$tmp/br-desc" \
    && ok || { fail "brushed .bsdf structure"; cat "$tmp/br-desc"; }
"$lamina" export --check "$tmp/br.bsdf" --study "$tmp/br" --config brushed-al-a0.2-a1.05x.3 \
    --source wb20 >"$tmp/br-check" 2>&1 || { fail "brushed --check"; cat "$tmp/br-check"; }
"$py" - "$tmp/br" "$tmp/br-check" "$src/src/python/lamina/arrays.py" <<'PY' && ok || { fail "brushed .bsdf albedo against the study's table"; cat "$tmp/br-check"; }
import importlib.util, json, re, sys
import numpy as np
study, check, arrays_py = sys.argv[1:4]
spec = importlib.util.spec_from_file_location("arrays", arrays_py)
arrays = importlib.util.module_from_spec(spec)
spec.loader.exec_module(arrays)
d = f"{study}/configs/brushed-al-a0.2-a1.05x.3"
cfg = json.load(open(f"{d}/config.json"))
t = arrays.read_array(f"{d}/tables.lza")[cfg["sources"].index("wb20")].astype(np.float64)
n_theta, n_phi = t.shape[2], t.shape[3]
te, pe = np.linspace(0, np.pi / 2, n_theta + 1), np.linspace(0, 2 * np.pi, n_phi + 1)
omega = np.outer(np.diff(np.sin(te) ** 2), np.diff(pe)) / 2    # one patch of the unfolded grid
rows = {}
for line in open(check):
    m = re.match(r"\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+[\d.]+%", line)
    if m:
        rows[(float(m[1]), float(m[2]))] = float(m[4])          # the file's albedo (luminance)
y = np.array([0.2126, 0.7152, 0.0722])
found = 0
for i, (ti, pi) in enumerate(zip(cfg["theta_i"], cfg["phi_i"])):
    if ti != 45:
        continue
    table = float((np.einsum("tpc,tp->c", t[i, 0], omega) * y).sum())
    file = rows[(ti, pi)]
    assert abs(file / table - 1) < 0.02, (ti, pi, file, table)
    found += 1
assert found == 3, found
PY
# The reference of a brushed configuration holds three azimuths: no .bsdf of it.
"$lamina" export --study "$tmp/br" --config brushed-al-a0.2-a1.05x.3 --out "$tmp/br-ref.bsdf" >"$tmp/br-ref" 2>&1 \
    && fail "a brushed reference's .bsdf accepted" \
    || { grep -q "its light from φi = 0°, 45°, 90° only" "$tmp/br-ref" && ok || { fail "brushed reference message"; cat "$tmp/br-ref"; }; }

finish
