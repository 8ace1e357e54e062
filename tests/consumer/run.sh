#!/usr/bin/env bash
# Installs the build tree BUILD into a temporary prefix, then configures, builds and runs the
# consumer project against it, and, when BUILD has the Python module, imports the installed module
# (consumer.py) from the prefix alone. Usage: run.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
source=$(cd "$2" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$source/tests/consumer" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" >/dev/null
"$work/build/consumer"
test -x "$work/prefix/bin/cheval"
# The installed executable and its default vehicle file (PREFIX/share/cheval/vehicles).
test -f "$work/prefix/share/cheval/vehicles/flightgoggles.json"
"$work/prefix/bin/cheval" sim quadrotor --scenario hover --duration 1 -o "$work/flight" --quiet
cmp "$work/prefix/share/cheval/vehicles/flightgoggles.json" "$source/data/vehicles/flightgoggles.json"

# The Python module, when built: the interpreter and install folder are the build's own settings.
cached() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
if [ "$(cached CHEVAL_BUILD_PYTHON)" = ON ]; then
  site="$work/prefix/$(cached CHEVAL_PYTHON_INSTALL_DIR)"
  python=$(cached Python3_EXECUTABLE)
  test -f "$site/cheval/__init__.py"
  # From an empty folder with only the prefix on the path (-s: no user site-packages), so neither the
  # source nor the build tree can be imported instead.
  (cd "$work" && PYTHONPATH="$site" "$python" -s "$source/tests/consumer/consumer.py" "$site")
fi
