#!/usr/bin/env bash
# Byte-identical outputs of two focal builds: the check to run around a refactor.
#
#   bash scripts/compare_outputs.sh OLD_FOCAL NEW_FOCAL [WORK_DIR]
#
# OLD_FOCAL and NEW_FOCAL are two `focal` executables (say a worktree of the last commit built in
# build/release, and this tree's). The inputs are made once, by OLD_FOCAL: the eight analytic
# surfaces, regular and irregular, clean, with vertex noise and with normal noise, in PLY, OBJ and
# OFF, the scanned meshes of Debian's libcgal-demo data (no normals in the file), and point
# clouds of four surfaces with and without normals and noise, in PLY and XYZ. Every command
# below then runs with both executables and each output file (CSV, PLY, PNG, and what the
# command prints) is compared byte for byte. `generate` itself is compared too. The key mesh and
# cloud commands also run with --threads 1 and --threads 2 (the same bits for any count).
# Prints one line per difference and a closing "N passed, N failed"; exits 1 on any difference.
set -euo pipefail

old=$(realpath "$1")
new=$(realpath "$2")
work=${3:-$(mktemp -d)}
mkdir -p "$work/in" "$work/old" "$work/new"

passed=0
failed=0
compare() {  # compare NAME: $work/old/NAME vs $work/new/NAME
  # A file neither build wrote is the same on both sides: the command failed in both (say
  # `--normals file` on a scan without normals), and its .log, compared too, says how.
  if [[ ! -e $work/old/$1 && ! -e $work/new/$1 ]] || cmp -s "$work/old/$1" "$work/new/$1"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "DIFFERS: $1"
  fi
}

# run NAME ARGS...: runs `focal ARGS` with each executable in its own folder (outputs named in
# ARGS relative to it), keeps stdout + stderr and the exit code as NAME.log.
run() {
  local name=$1
  shift
  for side in old new; do
    local exe=$old
    [[ $side == new ]] && exe=$new
    (cd "$work/$side" && { "$exe" "$@" > "$name.log" 2>&1; echo "exit $?" >> "$name.log"; } || true)
    # Timings printed by -v differ from run to run: drop them.
    sed -i -E 's/ +[0-9]+(\.[0-9]+)? ?(ms|s)\b/ T/g' "$work/$side/$name.log"
  done
  compare "$name.log"
}

surfaces=(sphere ellipsoid torus cylinder saddle monkey-saddle helix-tube pear)
inputs=()
for surface in "${surfaces[@]}"; do
  for triangulation in regular irregular; do
    for noise in clean vnoise nnoise; do
      case $noise in
        clean) flags=() ;;
        vnoise) flags=(--position-noise 0.1) ;;
        nnoise) flags=(--normal-noise 0.05) ;;
      esac
      ext=ply
      [[ $noise == vnoise ]] && ext=obj
      [[ $triangulation == regular && $noise == nnoise ]] && ext=off
      name=$surface-$triangulation-$noise.$ext
      for side in old new; do
        exe=$old
        [[ $side == new ]] && exe=$new
        "$exe" generate "$surface" --triangulation "$triangulation" --vertices 1200 --seed 3 \
          "${flags[@]}" -o "$work/$side/gen-$name" --truth "$work/$side/gen-$name.truth.csv"
      done
      compare "gen-$name"
      compare "gen-$name.truth.csv"
      cp "$work/old/gen-$name" "$work/in/$name"
      inputs+=("$name")
    done
  done
done

scans=()
archive=/usr/share/doc/libcgal-dev/data.tar.gz
if [[ -f $archive ]]; then
  for scan in bunny00 fandisk elephant; do
    if tar -xzf "$archive" -O "data/meshes/$scan.off" > "$work/in/$scan.off" 2> /dev/null; then
      scans+=("$scan.off")
    else
      rm -f "$work/in/$scan.off"
    fi
  done
fi

for mesh in "${inputs[@]}" "${scans[@]}"; do
  in=$work/in/$mesh
  b=${mesh%.*}
  run "$b.info" info "$in"
  run "$b.default" -v curvature "$in" -o "$b.default.csv"
  compare "$b.default.csv"
  run "$b.default-ply" curvature "$in" -o "$b.default.ply"
  compare "$b.default.ply"
  run "$b.paper" curvature "$in" --paper -o "$b.paper.csv"
  compare "$b.paper.csv"
  run "$b.paper-ply" curvature "$in" --paper -o "$b.paper.ply" --ascii
  compare "$b.paper.ply"
  run "$b.triangle" curvature "$in" --method triangle -o "$b.triangle.csv"
  compare "$b.triangle.csv"
  run "$b.focal-mesh" focal-mesh "$in" -o "$b.fm"
  compare "$b.fm.focal1.ply"
  compare "$b.fm.focal2.ply"
  run "$b.focal-mesh-paper" focal-mesh "$in" --paper -o "$b.fmp"
  compare "$b.fmp.focal1.ply"
  compare "$b.fmp.focal2.ply"
done

# Every estimator option on a few meshes (each option is a separate code path).
for mesh in torus-irregular-clean.ply pear-irregular-vnoise.obj saddle-regular-nnoise.off \
            "${scans[@]:0:1}"; do
  in=$work/in/$mesh
  b=${mesh%.*}
  run "$b.lm" curvature "$in" --solver levenberg-marquardt -o "$b.lm.csv"
  compare "$b.lm.csv"
  run "$b.rings" curvature "$in" --rings 2 --weights gaussian -o "$b.rings.csv"
  compare "$b.rings.csv"
  for normals in area angle max file; do
    run "$b.$normals" curvature "$in" --normals "$normals" -o "$b.$normals.csv"
    compare "$b.$normals.csv"
  done
  # The key mesh commands on 1 and 2 threads.
  for t in 1 2; do
    run "$b.threads$t" curvature "$in" --threads "$t" -o "$b.threads$t.ply"
    compare "$b.threads$t.ply"
    run "$b.threads$t-csv" curvature "$in" --threads "$t" -o "$b.threads$t.csv"
    compare "$b.threads$t.csv"
    run "$b.paper-threads$t" curvature "$in" --paper --threads "$t" -o "$b.paper-threads$t.csv"
    compare "$b.paper-threads$t.csv"
    run "$b.triangle-threads$t" curvature "$in" --method triangle --threads "$t" \
      -o "$b.triangle-threads$t.csv"
    compare "$b.triangle-threads$t.csv"
    run "$b.focal-mesh-threads$t" focal-mesh "$in" --threads "$t" -o "$b.fm-threads$t"
    compare "$b.fm-threads$t.focal1.ply"
    compare "$b.fm-threads$t.focal2.ply"
    run "$b.normals-threads$t" normals "$in" --threads "$t" -o "$b.normals-threads$t.ply"
    compare "$b.normals-threads$t.ply"
  done
  run "$b.render-H" render "$in" -o "$b.H.png" --field H --size 320x240
  compare "$b.H.png"
  run "$b.render-class" render "$in" -o "$b.class.png" --field class --directions d1 \
    --size 320x240 --paper
  compare "$b.class.png"
  run "$b.render-focal" render "$in" -o "$b.focal.png" --focal-meshes --size 320x240
  compare "$b.focal.png"
done

# Point clouds: the irregular samples of four surfaces (one with a boundary), with exact
# normals, without normals, with position noise (with and without normals) and with normal
# noise, in PLY and XYZ.
clouds=()
for surface in sphere torus saddle helix-tube; do
  for variant in normals bare vnoise vnoise-bare nnoise; do
    case $variant in
      normals) flags=() ext=ply ;;
      bare) flags=(--no-normals) ext=xyz ;;
      vnoise) flags=(--position-noise 0.1) ext=xyz ;;
      vnoise-bare) flags=(--position-noise 0.1 --no-normals) ext=ply ;;
      nnoise) flags=(--normal-noise 0.05) ext=ply ;;
    esac
    name=cloud-$surface-$variant.$ext
    for side in old new; do
      exe=$old
      [[ $side == new ]] && exe=$new
      "$exe" generate "$surface" --cloud --vertices 3000 --seed 5 "${flags[@]}" \
        -o "$work/$side/gen-$name" --truth "$work/$side/gen-$name.truth.csv"
    done
    compare "gen-$name"
    compare "gen-$name.truth.csv"
    cp "$work/old/gen-$name" "$work/in/$name"
    clouds+=("$name")
  done
done

# Every cloud command with its default neighbourhoods, --k 16, --radius (about 30 neighbours
# on these samples) and, for curvature, --tiles 3; the default also on 1 and 2 threads.
for cloud in "${clouds[@]}"; do
  in=$work/in/$cloud
  b=${cloud%.*}
  run "$b.info" info "$in"
  run "$b.default" -v curvature "$in" -o "$b.default.csv"
  compare "$b.default.csv"
  run "$b.default-ply" curvature "$in" -o "$b.default.ply"
  compare "$b.default.ply"
  run "$b.k16" curvature "$in" --k 16 -o "$b.k16.csv"
  compare "$b.k16.csv"
  run "$b.radius" curvature "$in" --radius 0.2 -o "$b.radius.csv"
  compare "$b.radius.csv"
  run "$b.tiles" curvature "$in" --tiles 3 -o "$b.tiles.csv"
  compare "$b.tiles.csv"
  run "$b.normals" normals "$in" -o "$b.normals.ply"
  compare "$b.normals.ply"
  run "$b.normals-k16" normals "$in" --k 16 -o "$b.normals-k16.xyz"
  compare "$b.normals-k16.xyz"
  run "$b.normals-radius" normals "$in" --radius 0.2 -o "$b.normals-radius.ply"
  compare "$b.normals-radius.ply"
  run "$b.focal-mesh" focal-mesh "$in" -o "$b.fm"
  compare "$b.fm.focal1.ply"
  compare "$b.fm.focal2.ply"
  run "$b.focal-mesh-k16" focal-mesh "$in" --k 16 -o "$b.fmk"
  compare "$b.fmk.focal1.ply"
  compare "$b.fmk.focal2.ply"
  for t in 1 2; do
    run "$b.threads$t" curvature "$in" --threads "$t" -o "$b.threads$t.csv"
    compare "$b.threads$t.csv"
    run "$b.k16-threads$t" curvature "$in" --k 16 --threads "$t" -o "$b.k16-threads$t.ply"
    compare "$b.k16-threads$t.ply"
    run "$b.normals-threads$t" normals "$in" --threads "$t" -o "$b.normals-threads$t.ply"
    compare "$b.normals-threads$t.ply"
  done
done

# focal eval: every estimator against analytic truth (its own meshes).
run eval eval --csv eval.csv --markdown eval.md --vertices 800
compare eval.csv
compare eval.md

echo "outputs of $old and $new in $work"
echo "$passed passed, $failed failed"
[[ $failed == 0 ]]
