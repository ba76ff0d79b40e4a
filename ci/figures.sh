#!/usr/bin/env bash
# Measures the figures the README and the docs quote and writes them to docs/figures.md, the one
# place they live: the Cortex-M4F run under QEMU (ci/firmware.sh), the engine's memory, and the
# accuracy on the development scenes and on the extra views, side by side. Run it after a change
# that moves a figure, and commit the file with the change.
#
#   bash ci/figures.sh            (scenes/dev, and ../shared/scenes/views when present; about 35 minutes)
set -euo pipefail
cd "$(dirname "$0")/.."

OUT=docs/figures.md
TMP=target/figures
VIEWS=../shared/scenes/views
mkdir -p "$TMP"

bash ci/firmware.sh >"$TMP/firmware.txt" 2>&1 || { tail -n 40 "$TMP/firmware.txt"; exit 1; }
cargo run --release --example figures >"$TMP/memory.md" 2>"$TMP/memory.err"
# The README's picture: what the demo draws.
cargo run --release --example complete >"$TMP/demo.txt" 2>&1
cp target/demo/builtin.png docs/builtin.png
# The pictures of three development scenes: docs/can.png, docs/bowl.png, docs/box.png.
for picture in can:ycb_005_tomato_soup_can_wrist_0 bowl:ycb_024_bowl_wrist_0 box:ycb_036_wood_block_wrist_1; do
    cargo run --release --example complete -- "scenes/dev/${picture#*:}.json" \
        --png "docs/${picture%%:*}.png" >>"$TMP/demo.txt" 2>&1
done
# `evaluate NAME DIR [OPTION...]`: the evaluation of DIR with the options, into $TMP/NAME.md.
evaluate() {
    local name=$1 dir=$2
    shift 2
    cargo run --release --example evaluate -- "$dir" "$@" \
        --out-md "$TMP/$name.md" >"$TMP/$name.txt" 2>&1 || { tail -n 20 "$TMP/$name.txt"; exit 1; }
}
# Each with the mask and table given, then without the table, without the mask, and with neither;
# then with neither, the engine told that nothing touches the object (no parting at creases nor
# splitting at necks); then, mask and table given, with the contact term for mirrors off level
# too (opt-in).
for set in "dev scenes/dev" "views $VIEWS"; do
    name=${set%% *} dir=${set#* }
    [ -d "$dir" ] || continue
    evaluate "$name" "$dir" --sweep no-table,no-mask,no-input
    evaluate "${name}_one_object" "$dir" --sweep no-input --one-object
    evaluate "${name}_tilted" "$dir" --tilted-contact
done
# Objects the development scenes do not hold: the test kit's synthetic ones.
cargo run --release --example synthetic >"$TMP/synthetic.md" 2>"$TMP/synthetic.err" ||
    { cat "$TMP/synthetic.err"; exit 1; }
# ... rendered with the Kinect's lateral noise, the search modelling it (the default) or not.
cargo run --release --example synthetic -- --lateral-jitter >"$TMP/lateral_on.md" \
    2>"$TMP/synthetic.err" || { cat "$TMP/synthetic.err"; exit 1; }
cargo run --release --example synthetic -- --lateral-jitter --model-lateral off \
    >"$TMP/lateral_off.md" 2>"$TMP/synthetic.err" || { cat "$TMP/synthetic.err"; exit 1; }
# ... rendered with the shadow of the Kinect's projector.
cargo run --release --example synthetic -- --shadow >"$TMP/shadow.md" 2>"$TMP/synthetic.err" ||
    { cat "$TMP/synthetic.err"; exit 1; }
# The same at range and with a noisier sensor (the match σ's floor against the sensor's noise).
for setting in "--distance 0.8" "--distance 1.1" "--noise-scale 2"; do
    # shellcheck disable=SC2086 # the setting is a flag and its value
    cargo run --release --example synthetic -- $setting >"$TMP/range_${setting##* }.md" \
        2>"$TMP/synthetic.err" || { cat "$TMP/synthetic.err"; exit 1; }
done
# ... and the Kinect at range with its lateral noise, which the search models (the default).
cargo run --release --example synthetic -- --distance 1.1 --lateral-jitter >"$TMP/range_1.1_lateral.md" \
    2>"$TMP/synthetic.err" || { cat "$TMP/synthetic.err"; exit 1; }
# ... and with their axial noise correlated between neighbouring pixels as the real frames' is.
cargo run --release --example synthetic -- --distance 1.1 --lateral-jitter --correlated-noise \
    >"$TMP/range_1.1_correlated.md" 2>"$TMP/synthetic.err" || { cat "$TMP/synthetic.err"; exit 1; }
# ... through the real frames' camera at their range, with and without mask and table, and
# without them told that nothing touches the object; with the projector's shadow, and with it
# glossy tops that read nothing.
for setting in "" "--no-input" "--no-input --one-object" "--shadow" "--shadow --glossy-tops"; do
    name=$(echo "$setting" | tr -d '-' | tr ' ' '_')
    # shellcheck disable=SC2086 # optional flags
    cargo run --release --example synthetic -- --registered --distance 0.9 --lateral-jitter $setting \
        >"$TMP/registered${name:+_$name}.md" 2>"$TMP/synthetic.err" ||
        { cat "$TMP/synthetic.err"; exit 1; }
done
# How the noise of the real frames and of the scenes correlates between neighbouring pixels.
NOISE_DIRS=scenes/dev
[ -d "$VIEWS" ] && NOISE_DIRS="$NOISE_DIRS $VIEWS"
[ -d ../shared/scenes/real ] && NOISE_DIRS="../shared/scenes/real $NOISE_DIRS"
# shellcheck disable=SC2086 # one argument per folder
cargo run --release --example noise -- $NOISE_DIRS >"$TMP/noise.md" 2>"$TMP/noise.err" ||
    { cat "$TMP/noise.err"; exit 1; }
# ... and how many readings are missing beside their depth jumps.
# shellcheck disable=SC2086 # one argument per folder
cargo run --release --example noise -- --gaps $NOISE_DIRS >"$TMP/gaps.md" 2>"$TMP/noise.err" ||
    { cat "$TMP/noise.err"; exit 1; }
# Part symmetries: the part tests' cases over many noise draws.
cargo run --release --example parts >"$TMP/parts.md" 2>"$TMP/parts.err" ||
    { cat "$TMP/parts.err"; exit 1; }
# ... rendered with the Kinect's lateral noise, the search modelling it.
cargo run --release --example parts -- --lateral-jitter >"$TMP/parts_lateral.md" \
    2>"$TMP/parts.err" || { cat "$TMP/parts.err"; exit 1; }
# Object selection: the synthetic clutter cases, and the real frames' overlays in docs/real/.
REAL=../shared/scenes/real
cargo run --release --example targets -- "$REAL" docs/real >"$TMP/clutter.md" 2>"$TMP/clutter.err" ||
    { cat "$TMP/clutter.err"; exit 1; }

# The first line of the firmware's output that starts with $1 (target build: the measuring run).
firmware() { grep -m1 "^$1" "$TMP/firmware.txt" | sed "s/^$1 *//"; }
# The "## Totals" section of an evaluation, without its heading.
totals() { awk '/^## Totals/ { on = 1; next } on && /^## / { exit } on' "$TMP/$1.md"; }
# The table of its missing-input sweeps: the scenes as recorded, without the table, without the
# mask, with neither; then with neither and one object in view.
sweep_rows() { awk '/^### Missing table plane or mask/ { on = 1; next } on && /^#/ { exit } on && /^\|/' "$1"; }
# The headline lines of an evaluation's totals: classes, validity, completion, free space, work.
brief() {
    totals "$1" | grep -E '^- (type against|strongest symmetry valid|completion|generated points|time)'
}
no_input() {
    sweep_rows "$TMP/$1.md"
    sweep_rows "$TMP/$1_one_object.md" | grep '^| no table plane, no mask' |
        sed 's/^| no table plane, no mask |/| neither, one object in view (`--one-object`) |/'
}

{
    echo "# Figures"
    echo
    echo "Written by \`bash ci/figures.sh\` with \`src/\` as at commit \`$(git log -1 --format=%h -- src)\`$(git diff --quiet HEAD -- src || echo ' (with uncommitted changes to src/)'); do not edit by hand."
    echo
    echo "## Cortex-M4F (QEMU \`mps2-an386\`, \`-icount shift=3\`: instruction counts)"
    echo
    echo "The built-in scene, \`DefaultEngine\`, default configuration, polled at \`RECOMMENDED_BUDGET\`"
    echo "(\`ci/firmware.sh\`; CI fails if a poll exceeds 100 000 instructions or the digest differs"
    echo "from the host's)."
    echo
    echo "| measure | figure |"
    echo "|---|---|"
    echo "| instructions, whole search | $(firmware 'instructions total:') |"
    echo "| largest poll | $(firmware 'instructions max poll:') |"
    echo "| polls | $(firmware 'polls:') |"
    echo "| preparing | $(firmware 'stage preparing:') |"
    echo "| searching | $(firmware 'stage searching:') |"
    echo "| completing | $(firmware 'stage completing:') |"
    echo "| 1 kHz control loop | $(firmware 'control loop: 1000 Hz tick') |"
    echo "| peak stack | $(firmware 'peak stack:') |"
    echo "| RAM | $(firmware 'ram:') |"
    echo "| result | $(firmware 'work units:') |"
    echo "| digest (host = target) | $(firmware 'digest:') |"
    echo
    echo "The completion's dense pass, which the default firmware's output has no room for: the same"
    echo "scene with \`--features firmware-dense\` (\`examples/firmware/capacity.rs\`), checked the same way."
    echo
    echo "| measure | figure |"
    echo "|---|---|"
    echo "| object | $(firmware 'dense object:') |"
    echo "| points | $(firmware 'dense points:') |"
    echo "| largest poll | $(firmware 'dense instructions max poll:') |"
    echo "| completing | $(firmware 'dense stage completing:') |"
    echo "| RAM | $(firmware 'dense ram:') |"
    echo "| digest (host = target) | $(firmware 'dense digest:') |"
    echo
    echo "## Memory"
    echo
    cat "$TMP/memory.md"
    echo
    echo "## Accuracy"
    echo
    echo "\`cargo run --release --example evaluate -- scenes/dev\` and the same on the extra views (mask and table"
    echo "given, default configuration). A symmetry is *valid* when every map moves the ground-truth"
    echo "surface onto itself (mean <= 4 mm, p90 <= 8 mm, p99 <= 12 mm); completion coverage /"
    echo "precision / F at 5 mm against the whole surface."
    echo
    echo "### Development scenes (scenes/dev)"
    echo
    totals dev
    echo
    echo "### Extra views of the same objects ($VIEWS)"
    echo
    if [ -d "$VIEWS" ]; then totals views; else echo "(not measured: $VIEWS absent)"; fi
    echo
    echo "### Without the mask or the table"
    echo
    echo "The same scenes without the table plane, without the mask, and with neither given"
    echo "(\`--sweep no-table,no-mask,no-input\`): the engine fits the support plane and segments the"
    echo "object itself (the object at the optical axis). The first row of each table is the scenes as"
    echo "recorded; completion and free space are judged with the recorded mask. The last row: neither"
    echo "given, and the engine told that nothing touches the object (\`PrepareConfig::with_one_object\`:"
    echo "no parting at concave creases nor splitting at necks, where touching objects meet and where"
    echo "a handle or a neck meets its body)."
    echo
    echo "Development scenes:"
    echo
    no_input dev
    if [ -d "$VIEWS" ]; then
        echo
        echo "Extra views:"
        echo
        no_input views
    fi
    echo
    echo "### Mirrors off level (\`ModelConfig::tilted_contact\`, opt-in)"
    echo
    echo "Mask and table given, the contact term also crediting a mirror tilted beyond 5° of level"
    echo "that, halfway up the object, sends its top within a match's reach of the support"
    echo "(\`--tilted-contact\`); the default's figures are above."
    echo
    echo "Development scenes:"
    echo
    brief dev_tilted
    if [ -d "$VIEWS" ]; then
        echo
        echo "Extra views:"
        echo
        brief views_tilted
    fi
    echo
    echo "### Synthetic objects (other shapes)"
    echo
    echo "\`cargo run --release --example synthetic\`: the test kit's synthetic objects (primitives,"
    echo "objects made of parts, objects lying on their side), each from 12 views (0.5 m; elevations 30°,"
    echo "45°, 60°; azimuths 0°, 60°, 150°, 260°) and 2 noise draws, mask and table given. *Valid*: every"
    echo "map of the strongest symmetry takes the sampled points (moved onto the true surface: the"
    echo "symmetry, not the sensor's noise, is judged) onto the true surface (mean <= 4 mm, p90 <= 8 mm,"
    echo "p99 <= 12 mm); for the asymmetric object, none found or a near-symmetry within those bounds"
    echo "(*exact class*: none found). The renderer imitates no lateral noise and the search is told so"
    echo "(\`synth::SENSOR\`)."
    echo
    cat "$TMP/synthetic.md"
    echo
    echo "The same objects rendered with the Kinect's lateral noise (\`--lateral-jitter\`: each reading"
    echo "taken along a ray displaced by the Kinect's lateral σ, \`KINECT_LATERAL_PX\`), searched with the"
    echo "default sensor, which models it, or without that model (\`--model-lateral off\`):"
    echo
    echo "| sensor model | scenes | valid | exact class | missed | failed |"
    echo "|---|---|---|---|---|---|"
    grep '^| \*\*all' "$TMP/lateral_on.md" | sed 's/^| \*\*all\*\* | |/| lateral noise (default) |/'
    grep '^| \*\*all' "$TMP/lateral_off.md" | sed 's/^| \*\*all\*\* | |/| no lateral noise |/'
    echo
    echo "The same objects rendered with the shadow of the Kinect's projector (\`--shadow\`: no reading"
    echo "where the projector, \`KINECT_BASELINE\` right of the camera, cannot light the surface: a band"
    echo "beside each near edge, and surfaces turned from it), searched with the default sensor:"
    echo
    cat "$TMP/shadow.md"
    echo
    echo "At range and with a noisier camera (\`--distance M\`; \`--noise-scale S\`: the rendered axial"
    echo "noise and the search's sensor model both S times the Kinect's), with the default match σ"
    echo "(\`ModelConfig::sigma_min\`, a constant floor that does not follow the sensor's noise):"
    echo
    echo "| camera | scenes | valid | exact class | missed | failed |"
    echo "|---|---|---|---|---|---|"
    grep '^| \*\*all' "$TMP/synthetic.md" | sed 's/^| \*\*all\*\* | |/| Kinect, 0.5 m (above) |/'
    grep '^| \*\*all' "$TMP/range_0.8.md" | sed 's/^| \*\*all\*\* | |/| Kinect, 0.8 m |/'
    grep '^| \*\*all' "$TMP/range_1.1.md" | sed 's/^| \*\*all\*\* | |/| Kinect, 1.1 m |/'
    grep '^| \*\*all' "$TMP/range_2.md" | sed 's/^| \*\*all\*\* | |/| twice the Kinect'"'"'s noise, 0.5 m |/'
    echo
    echo "The Kinect at 1.1 m with its lateral noise (\`--distance 1.1 --lateral-jitter\`), searched with"
    echo "the default sensor, which models it: the camera as a robot's head sees a table-top object."
    echo
    cat "$TMP/range_1.1_lateral.md"
    echo
    echo "The same with the axial noise correlated between neighbouring pixels as the real frames'"
    echo "(\`--correlated-noise\`: \`Artefacts::xtion_correlated\`, the real frames' kernel in milliradians at"
    echo "this camera's focal length; see the noise correlation below):"
    echo
    echo "| rendering | scenes | valid | exact class | missed | failed |"
    echo "|---|---|---|---|---|---|"
    grep '^| \*\*all' "$TMP/range_1.1_lateral.md" | sed 's/^| \*\*all\*\* | |/| independent noise (above) |/'
    grep '^| \*\*all' "$TMP/range_1.1_correlated.md" | sed 's/^| \*\*all\*\* | |/| correlated noise |/'
    echo
    echo "Through the real frames' camera at their range (\`--registered --distance 0.9 --lateral-jitter\`:"
    echo "\`REAL_FRAME_INTRINSICS\`, 640 x 480, f = 1067 px, 0.1 mm units, an Xtion's depth registered to"
    echo "its colour camera, each pixel the reading of its nearest depth sensor pixel), mask and table"
    echo "given, then neither (\`--no-input\`: the search fits the support and segments the object),"
    echo "then neither with the search told that nothing touches the object (\`--one-object\`):"
    echo
    echo "| input | scenes | valid | exact class | missed | failed |"
    echo "|---|---|---|---|---|---|"
    grep '^| \*\*all' "$TMP/registered.md" | sed 's/^| \*\*all\*\* | |/| mask and table |/'
    grep '^| \*\*all' "$TMP/registered_noinput.md" | sed 's/^| \*\*all\*\* | |/| neither |/'
    grep '^| \*\*all' "$TMP/registered_noinput_oneobject.md" |
        sed 's/^| \*\*all\*\* | |/| neither, one object in view (`--one-object`) |/'
    echo
    echo "Object by object, neither given:"
    echo
    cat "$TMP/registered_noinput.md"
    echo
    echo "The same camera, mask and table given, with the projector's shadow (\`--shadow\`), then also"
    echo "with glossy tops (\`--glossy-tops\`: the objects' faces within 20° of up read nothing, as a"
    echo "metal lid or a glossy top reflects the projected pattern away; the real frames' coffee can"
    echo "returns few readings from its lid):"
    echo
    echo "| rendering | scenes | valid | exact class | missed | failed |"
    echo "|---|---|---|---|---|---|"
    grep '^| \*\*all' "$TMP/registered_shadow.md" | sed 's/^| \*\*all\*\* | |/| shadow |/'
    grep '^| \*\*all' "$TMP/registered_shadow_glossytops.md" |
        sed 's/^| \*\*all\*\* | |/| shadow and glossy tops |/'
    echo
    echo "Object by object, with glossy tops:"
    echo
    cat "$TMP/registered_shadow_glossytops.md"
    echo
    echo "### Sensor noise correlation"
    echo
    echo "\`cargo run --release --example noise -- DIRS\` (\`sfs_testkit::correlation\`): the planar"
    echo "patches of each depth image (24 px squares at 640 columns, residual RMS about their"
    echo "least-squares plane within twice the sensor model's σ), the autocorrelation ρ of their"
    echo "residuals at 1, 2 and 4 pixels, and the σ of the Gaussian kernel that correlates adjacent"
    echo "pixels as much, in pixels and in milliradians (pixels over the focal length). The real"
    echo "frames' depth is registered to their colour camera (f = 1067 px); the scenes' renderer draws"
    echo "each pixel's noise on its own."
    echo
    cat "$TMP/noise.md"
    echo
    echo "### Readings missing beside depth jumps"
    echo
    echo "\`cargo run --release --example noise -- --gaps DIRS\` (\`sfs_testkit::gaps\`): along the image"
    echo "rows, every two consecutive readings farther apart in depth than a surface at 85° incidence"
    echo "steps between neighbouring pixels (three σ on top) are a jump; the pixels without a reading"
    echo "between them are the run it leaves. By the side the nearer surface lies on: its left (the run"
    echo "along the nearer surface's right side) or its right."
    echo
    cat "$TMP/gaps.md"
    echo
    echo "### Part symmetries (\`DomainConfig::parts\`, opt-in)"
    echo
    echo "\`cargo run --release --example parts\`: the checks \`tests/domains.rs\` asserts"
    echo "(\`sfs_testkit::parts::CASES\`), each view searched under 12 draws of the Kinect noise model: a"
    echo "part is found when a domain covers it with its own symmetry (80 % of its points, under 10 % of"
    echo "the domain elsewhere, within 3° and 10 mm). Each check claims the part found (on at least 8"
    echo "draws) or is a known gap (at least 2): \`parts::Claim\`."
    echo
    cat "$TMP/parts.md"
    echo
    echo "The same views rendered with the Kinect's lateral noise too (a thin part's silhouette pixels"
    echo "read the surface a pixel or two away), searched with the default sensor model, which models"
    echo "it (\`parts -- --lateral-jitter\`); the claims are those asserted without it:"
    echo
    cat "$TMP/parts_lateral.md"
    echo
    echo "## Object selection in clutter (no mask, no table)"
    echo
    echo "\`cargo run --release --example targets -- $REAL docs/real\`. The synthetic clutter cases of the"
    echo "test kit (\`sfs_testkit::clutter\`: 24 frames of 2-5 touching objects, a floor and a wall or a"
    echo "small support, Kinect noise, flying pixels), each object named by a target; IoU of the chosen"
    echo "region with the object's true mask, on the sampling lattice."
    echo
    cat "$TMP/clutter.md"
    echo
    echo "Real frames (no ground truth): every object named by a pixel, the regions chosen drawn over the"
    echo "colour images, and the symmetry found for each: [docs/real/targets.md](real/targets.md)."
} >"$OUT"
echo "wrote $OUT"
