#!/usr/bin/env bash
# The library as a user gets it (ctest InstallAndEmbed): installs the build tree BUILD into a
# temporary prefix, copies EXAMPLE (examples/embed) out of the source tree, configures it with
# find_package(nimbus) from that prefix alone, builds it, runs it, and checks its image. The
# installed nimbus executable must find its scenes without the checkout, and pkg-config must
# describe the library.
#
# Usage: tools/test_install.sh BUILD EXAMPLE
set -euo pipefail
build=$1
example=$2
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"

cmake --install "$build" --prefix "$prefix" > "$work/install.log"
for f in lib/libnimbus_core.a lib/nimbus_openvdb.so lib/cmake/nimbus/nimbusConfig.cmake \
         lib/cmake/nimbus/nimbusConfigVersion.cmake lib/pkgconfig/nimbus.pc \
         include/nimbus/nimbus.h bin/nimbus share/nimbus/scenes/demo.json \
         share/nimbus/tools/plot_segments.py share/nimbus/tools/exr_to_pfm_layers.py; do
  [ -e "$prefix/$f" ] || { echo "test_install: $f was not installed" >&2; exit 1; }
done
# The public headers only (docs/api.md): the integrator's templates, for one, stay private.
for f in include/nimbus/render/integrator.h include/nimbus/tracking/spectral_mis.h \
         include/nimbus/experiments/experiment.h; do
  [ ! -e "$prefix/$f" ] || { echo "test_install: the private header $f was installed" >&2; exit 1; }
done
headers=$(find "$prefix/include/nimbus" -name '*.h' | wc -l)
echo "test_install: $headers headers installed"

cp -r "$example" "$work/embed"
cmake -S "$work/embed" -B "$work/embed-build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" > "$work/configure.log" ||
  { cat "$work/configure.log" >&2; exit 1; }
cmake --build "$work/embed-build" -j"$(nproc)" > "$work/build.log" ||
  { cat "$work/build.log" >&2; exit 1; }
"$work/embed-build/embed" "$work/out.png"
[ -s "$work/out.png" ] || { echo "test_install: the example wrote no image" >&2; exit 1; }
head -c 8 "$work/out.png" | od -An -c | grep -q "P   N   G" ||
  { echo "test_install: the example's image is not a PNG" >&2; exit 1; }

# pkg-config knows the library and where its headers are.
PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs nimbus | grep -q -- "-lnimbus_core" ||
  { echo "test_install: pkg-config does not describe nimbus" >&2; exit 1; }

# The installed executable runs an experiment from the installed scenes, away from the checkout.
(cd "$work" && "$prefix/bin/nimbus" experiment segments --quick --no-plot --out "$work/exp" > /dev/null)
[ -s "$work/exp/segments.csv" ] || { echo "test_install: the installed nimbus ran no experiment" >&2; exit 1; }
# It reads a VDB scene through the installed OpenVDB module (lib/nimbus_openvdb.so, issue 45).
(cd "$work" && "$prefix/bin/nimbus" render "$prefix/share/nimbus/scenes/vdb_fire.json" --spp 1 \
  --set film.width=16 --set film.height=12 -q -o "$work/fire.png") ||
  { echo "test_install: the installed nimbus does not render a VDB scene" >&2; exit 1; }
# The Python package, where the build has it: installed in Debian's layout, imported from there
# alone, running an experiment from the installed scenes.
python="$prefix/lib/python3/dist-packages"
if [ -d "$build/python/nimbus" ]; then
  [ -f "$python/nimbus/__init__.py" ] || { echo "test_install: the Python package was not installed" >&2; exit 1; }
  (cd "$work" && PYTHONPATH="$python" /usr/bin/python3 -c \
    "import nimbus; assert nimbus.__file__.startswith('$python'); nimbus.experiment('segments', quick=True)
nimbus.render(nimbus.load_file('$prefix/share/nimbus/scenes/vdb_fire.json', {'film.width': 8, 'film.height': 6}), spp=1)") ||
    { echo "test_install: the installed Python package does not run" >&2; exit 1; }
fi
# The Blender add-on, where the build has it and Blender is installed: from the install alone
# it finds the installed module (its paths.json) and renders F12 (docs/blender.md).
addon="$prefix/share/nimbus/blender/addons/nimbus_blender"
if [ -d "$build/blender/addons/nimbus_blender" ]; then
  [ -f "$addon/__init__.py" ] && [ -f "$addon/paths.json" ] ||
    { echo "test_install: the Blender add-on was not installed" >&2; exit 1; }
  if command -v blender > /dev/null; then
    cat > "$work/f12.py" <<PY
import bpy, addon_utils
addon_utils.enable("nimbus_blender", default_set=True)
from nimbus_blender import backend
module = backend.load_module()
assert module is not None and module.__file__.startswith("$python"), module
scene = bpy.context.scene
scene.render.engine = "NIMBUS"
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 16, 12, 100
scene.nimbus.spp = 1
scene.render.filepath = "$work/f12.png"
bpy.ops.render.render(write_still=True)
PY
    (cd "$work" && env -u PYTHONPATH BLENDER_USER_SCRIPTS="$prefix/share/nimbus/blender" \
      blender -b --factory-startup --python-exit-code 1 -P "$work/f12.py" > "$work/blender.log" 2>&1) ||
      { tail -20 "$work/blender.log" >&2; echo "test_install: the installed add-on does not render" >&2; exit 1; }
    [ -s "$work/f12.png" ] || { echo "test_install: the installed add-on wrote no image" >&2; exit 1; }
    echo "test_install: the installed Blender add-on rendered F12 with the installed module"
  fi
fi
echo "test_install: installed, built examples/embed outside the tree, rendered, ran an experiment"
