#!/usr/bin/env bash
# Frame times of the web viewer (`lumigauss view`) in headless Chromium with software WebGL (SwiftShader):
# for each model size, a random relightable model (a ball on a ground disc, written as an ASCII PLY in the
# official LumiGauss layout) is served with the hidden --bench-report flag, the page is opened with
# ?bench=FRAMES, renders FRAMES frames while the orbit camera turns once around (each frame waited for with a
# one-pixel read-back, so GPU work is included), and reports; then one table is printed.
#
#   bench/viewer_bench.sh [--build DIR] [--sizes "50000 200000"] [--frames 30] [--window 1280,720]
#                         [--mode shadowed] [--out DIR]
#
# Columns: splats, canvas size, median and p90 frame time (ms), median depth-sort time in the Web Worker
# (ms), median interval between animation frames (ms). Needs chromium (scripts/setup.sh installs it).
set -euo pipefail
cd "$(dirname "$0")/.."

build=build
sizes="50000 200000"
frames=30
window=1280,720
mode=shadowed
out=""
while [[ $# -gt 0 ]]; do
    case "$1" in
        --build) build="$2"; shift 2 ;;
        --sizes) sizes="$2"; shift 2 ;;
        --frames) frames="$2"; shift 2 ;;
        --window) window="$2"; shift 2 ;;
        --mode) mode="$2"; shift 2 ;;
        --out) out="$2"; shift 2 ;;
        *) echo "bench/viewer_bench.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
done
bin="$build/lumigauss"
[[ -x "$bin" ]] || { echo "bench/viewer_bench.sh: '$bin' not found: build first (or pass --build DIR)" >&2; exit 2; }
chromium=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
[[ -n "$chromium" ]] || { echo "bench/viewer_bench.sh: chromium not found (apt-get install chromium)" >&2; exit 2; }
out="${out:-$(mktemp -d /tmp/viewer_bench.XXXXXX)}"
mkdir -p "$out"

# A relightable model of $1 surfels to $2: one third on a ball of radius 1, the rest on a ground disc of
# radius 4 at z = -1 (up +z); transfer = clamped-cosine lobe scaled by a fake ambient occlusion.
make_model() {
    awk -v n="$1" -v seed=7 '
    function lobe(nx, ny, nz, occ, out,    a0, a1, a2, k) {
        a0 = 3.141592653589793; a1 = 2 * a0 / 3; a2 = a0 / 4
        out[0] = a0 * 0.28209479177387814
        out[1] = a1 * 0.4886025119029199 * ny; out[2] = a1 * 0.4886025119029199 * nz
        out[3] = a1 * 0.4886025119029199 * nx
        out[4] = a2 * 1.0925484305920792 * nx * ny; out[5] = a2 * 1.0925484305920792 * ny * nz
        out[6] = a2 * 0.31539156525252005 * (3 * nz * nz - 1); out[7] = a2 * 1.0925484305920792 * nx * nz
        out[8] = a2 * 0.5462742152960396 * (nx * nx - ny * ny)
        for (k = 0; k < 9; ++k) out[k] *= occ
    }
    function emit(x, y, z, nx, ny, nz, occ, cell, r, g, b,    P, N, k, c, line, qw, qx, qy, ql, s) {
        lobe(nx, ny, nz, occ, P); lobe(-nx, -ny, -nz, occ, N)
        line = sprintf("%.6f %.6f %.6f 0 0 0", x, y, z)
        for (c = 0; c < 3; ++c) line = line sprintf(" %.6f", P[0])
        for (c = 0; c < 3; ++c) for (k = 1; k < 9; ++k) line = line sprintf(" %.6f", P[k])
        for (c = 0; c < 3; ++c) line = line sprintf(" %.6f", N[0])
        for (c = 0; c < 3; ++c) for (k = 1; k < 9; ++k) line = line sprintf(" %.6f", N[k])
        line = line sprintf(" %.6f %.6f %.6f 2.2", (r - 0.5) / 0.28209479177387814,
                            (g - 0.5) / 0.28209479177387814, (b - 0.5) / 0.28209479177387814)
        s = log(0.6 * cell)
        qw = 1 + nz; qx = -ny; qy = nx
        if (qw < 1e-6) { qw = 0; qx = 1; qy = 0 }
        ql = sqrt(qw * qw + qx * qx + qy * qy)
        print line sprintf(" %.6f %.6f %.6f %.6f %.6f 0", s, s, qw / ql, qx / ql, qy / ql)
    }
    BEGIN {
        srand(seed); pi = 3.141592653589793
        nb = int(n / 3); ng = n - nb
        print "ply"; print "format ascii 1.0"; print "element vertex " n
        split("x y z nx ny nz", names, " "); for (i = 1; i <= 6; ++i) print "property float " names[i]
        for (i = 0; i < 3; ++i) print "property float f_dc_positive_" i
        for (i = 0; i < 24; ++i) print "property float f_rest_positive_" i
        for (i = 0; i < 3; ++i) print "property float f_dc_negative_" i
        for (i = 0; i < 24; ++i) print "property float f_rest_negative_" i
        for (i = 0; i < 3; ++i) print "property float albedo_" i
        print "property float opacity"; print "property float scale_0"; print "property float scale_1"
        for (i = 0; i < 4; ++i) print "property float rot_" i
        print "end_header"
        cb = sqrt(4 * pi / nb); cg = sqrt(16 * pi / ng)
        for (i = 0; i < nb; ++i) {
            z = 2 * rand() - 1; phi = 2 * pi * rand(); rr = sqrt(1 - z * z)
            checker = (int((phi / pi) * 4) + int((z + 1) * 3)) % 2
            emit(rr * cos(phi), rr * sin(phi), z, rr * cos(phi), rr * sin(phi), z, 0.55 + 0.225 * (z + 1), cb,
                 checker ? 0.8 : 0.25, 0.35, checker ? 0.2 : 0.7)
        }
        for (i = 0; i < ng; ++i) {
            rr = 4 * sqrt(rand()); phi = 2 * pi * rand()
            emit(rr * cos(phi), rr * sin(phi), -1, 0, 0, 1, 1 - 0.75 * exp(-rr * rr * 1.5), cg, 0.55,
                 int(rr * 2) % 2 ? 0.6 : 0.5, 0.45)
        }
    }' > "$2"
}

# A sky-like environment: bright from above, warmer from +x.
printf '%s\n' "1.4 1.35 1.3" "0.1 0.1 0.15" "0.7 0.65 0.6" "0.45 0.4 0.3" "0.05 0.05 0.05" \
    "0.1 0.1 0.08" "0.2 0.18 0.15" "0.15 0.12 0.1" "0.05 0.04 0.03" > "$out/env.txt"

# The value of "key" inside the object "section" of the report (pretty-printed by the server, one field a
# line).
field() {
    awk -v section="\"$2\": {" -v key="\"$3\":" '
        index($0, section) { inside = 1; next }
        inside && index($0, "}") { inside = 0 }
        inside && index($0, key) { gsub(/[ ,]/, "", $2); print $2; exit }' "$1"
}
top() { awk -v key="\"$2\":" 'index($0, key) == 3 { gsub(/[ ,]/, "", $2); print $2; exit }' "$1"; }

# Runs one size; prints its table row.
bench_one() {
    local n="$1" dir="$out/$1"
    mkdir -p "$dir"
    [[ -f "$dir/model.ply" ]] || make_model "$n" "$dir/model.ply"
    rm -f "$dir/report.json"
    "$bin" view "$dir/model.ply" --port 0 --light "$out/env.txt" --bench-report "$dir/report.json" \
        > "$dir/server.log" 2>&1 &
    local server=$!
    local port=""
    for _ in $(seq 600); do
        port=$(grep -o 'http://127.0.0.1:[0-9]*' "$dir/server.log" | head -1 | sed 's/.*://' || true)
        [[ -n "$port" ]] && break
        kill -0 "$server" 2>/dev/null || break
        sleep 0.1
    done
    [[ -n "$port" ]] || { cat "$dir/server.log" >&2; echo "bench/viewer_bench.sh: the server did not start" >&2; exit 1; }
    # Its own session (and so process group), so that the browser and its helpers end together.
    setsid "$chromium" --headless=new --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
        --user-data-dir="$dir/profile" --window-size="$window" --force-device-scale-factor=1 --no-first-run \
        --no-default-browser-check --disable-extensions --disable-background-networking --disable-dev-shm-usage \
        --mute-audio "http://127.0.0.1:$port/?bench=$frames&mode=$mode" > "$dir/browser.log" 2>&1 &
    local browser=$!
    for _ in $(seq 1200); do kill -0 "$server" 2>/dev/null || break; sleep 0.5; done
    kill -TERM -- "-$browser" 2>/dev/null || true
    if kill -0 "$server" 2>/dev/null; then kill -INT "$server"; fi
    wait "$server" 2>/dev/null || true
    wait "$browser" 2>/dev/null || true
    [[ -f "$dir/report.json" ]] || { echo "bench/viewer_bench.sh: no report for $n splats" >&2; exit 1; }
    if grep -q '"errors": \[\]' "$dir/report.json"; then :; else
        echo "bench/viewer_bench.sh: the page reported errors for $n splats:" >&2
        cat "$dir/report.json" >&2
        exit 1
    fi
    printf '| %7s | %9s | %17.1f | %12.1f | %15.1f | %16.1f |\n' "$n" \
        "$(top "$dir/report.json" width)x$(top "$dir/report.json" height)" \
        "$(field "$dir/report.json" frame_ms median)" "$(field "$dir/report.json" frame_ms p90)" \
        "$(field "$dir/report.json" sort_ms median)" "$(field "$dir/report.json" raf_interval_ms median)"
}

echo "viewer bench: $frames frames per size, view $mode, window $window, headless Chromium + SwiftShader"
echo "renderer, CPU: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg); work folder $out"
echo
echo "|  splats |    canvas | median frame (ms) | p90 frame ms | sort ms (worker) | rAF interval (ms) |"
echo "|--------:|----------:|------------------:|-------------:|-----------------:|------------------:|"
for n in $sizes; do bench_one "$n"; done
