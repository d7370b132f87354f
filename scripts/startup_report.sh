#!/usr/bin/env bash
# Start-up and `info` cost beside OpenVDB's own tools, in one run (issue 16's
# checks), written to docs/startup.md:
#   vdbdag --version, vdbdag --help, vdbdag info SMALL.ssvdag  vs  vdb_print -version
#   vdbdag info of the .ssvdag of a 14.7M-voxel level set (the bunny at
#   d=1024) vs vdb_print -l of its .vdb (the figures info shows)
# Each figure: the median of 15 runs (wall time, peak RSS), alternating the
# commands so drift hits both alike. Usage: scripts/startup_report.sh [OUTDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-build/startup_report}
mkdir -p "$OUT"
V=build/vdbdag
[ -x "$V" ] || { echo "build/vdbdag is not built: scripts/setup.sh" >&2; exit 1; }
command -v vdb_print >/dev/null || { echo "needs vdb_print (openvdb-tools)" >&2; exit 1; }
build/vdbdag_make_samples "$OUT/samples" >/dev/null
$V encode "$OUT/samples/sphere_ls.vdb" -o "$OUT/small.ssvdag" -f -q >/dev/null
BUNNY=$OUT/bunny_d1024_ls.vdb
if [ ! -f "$BUNNY" ]; then
  # vdb_tool reads .obj, not the shared .off mesh: convert it.
  python3 - "../shared/data/meshes/bunny_watertight.off" "$OUT/bunny.obj" <<'PY'
import sys
lines = [l for l in open(sys.argv[1]).read().split('\n') if l.strip() and not l.startswith('#')]
nv, nf = map(int, lines[1].split()[:2])
with open(sys.argv[2], 'w') as out:
    for l in lines[2:2 + nv]: out.write('v ' + ' '.join(l.split()[:3]) + '\n')
    for l in lines[2 + nv:2 + nv + nf]:
        p = l.split(); out.write('f ' + ' '.join(str(int(x) + 1) for x in p[1:1 + int(p[0])]) + '\n')
PY
  vdb_tool -read "$OUT/bunny.obj" -mesh2ls d=1024 width=3 -write "$BUNNY" >/dev/null
fi
$V encode "$BUNNY" -o "$OUT/bunny_d1024.ssvdag" -f -q >/dev/null
python3 - "$V" "$OUT" <<'PY' | tee docs/startup.md
import os, resource, statistics, subprocess, sys, time
V, OUT = sys.argv[1], sys.argv[2]
def run(cmd):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    dt = time.perf_counter() - t
    if p.returncode != 0: sys.exit(f"{' '.join(cmd)} failed ({p.returncode})")
    return dt
def rss(cmd):
    p = subprocess.run(['/usr/bin/time', '-f', '%M'] + cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    return int(p.stderr.strip().split('\n')[-1]) / 1024
pairs = [
    ("`vdbdag --version`", [V, '--version'], "`vdb_print -version`", ['vdb_print', '-version']),
    ("`vdbdag --help`", [V, '--help'], "`vdb_print -version`", ['vdb_print', '-version']),
    ("`vdbdag info small.ssvdag` (120,414 voxels)", [V, 'info', f'{OUT}/small.ssvdag'], "`vdb_print -version`", ['vdb_print', '-version']),
    ("`vdbdag info bunny_d1024.ssvdag` (14.7M voxels)", [V, 'info', f'{OUT}/bunny_d1024.ssvdag'], "`vdb_print -l bunny_d1024_ls.vdb`", ['vdb_print', '-l', f'{OUT}/bunny_d1024_ls.vdb']),
]
print("# Start-up and `info` beside OpenVDB's tools\n")
print(f"Regenerate with `scripts/startup_report.sh` (median of 15 runs each, alternated; peak RSS of one more run). "
      f"Machine: {os.cpu_count()} cores. The .ssvdag of the bunny is {os.path.getsize(f'{OUT}/bunny_d1024.ssvdag'):,} bytes.\n")
print("| command | median ms | peak MB | baseline | median ms | peak MB | ratio |")
print("|---|---:|---:|---|---:|---:|---:|")
for name, cmd, bname, bcmd in pairs:
    a, b = [], []
    for _ in range(15):
        a.append(run(cmd)); b.append(run(bcmd))
    ma, mb = statistics.median(a) * 1000, statistics.median(b) * 1000
    print(f"| {name} | {ma:.1f} | {rss(cmd):.0f} | {bname} | {mb:.1f} | {rss(bcmd):.0f} | {ma / mb:.2f}x |")
PY
