#!/usr/bin/env bash
# Open3D for the lent GPU machine, which has no Debian packages: Debian 12's
# python3.11, numpy and python3-open3d (0.16.1) with every library they
# load but glibc's and GCC's runtime (the machine's newer ones serve), in
# OUT/open3d/ with run.sh (sets PYTHONHOME, PYTHONPATH, LD_LIBRARY_PATH and
# runs python3.11), packed as OUT/open3d.tar.xz. Here, as root, after
# tools/bench/setup.sh (docs/bench/surfaces, sessions 10 and 22):
#   bash tools/bench/open3d_bundle.sh .devo
# On the machine: tar xJf .devo/open3d.tar.xz -C /tmp && /tmp/open3d/run.sh -c "import open3d"
# (tools/bench/surface_peers.py --open3d-python /tmp/open3d/run.sh).
set -euo pipefail
OUT=${1:?out dir}
D=$OUT/open3d
rm -rf "$D" && mkdir -p "$D/lib" "$D/python/lib" "$D/python/dist-packages"
cp /usr/bin/python3.11 "$D/"
# The standard library less what a benchmark never imports.
tar -C /usr/lib -cf - --exclude=test --exclude=tests --exclude=__pycache__ --exclude=idlelib \
  --exclude=tkinter --exclude=ensurepip --exclude=lib2to3 --exclude='config-3.11*' \
  --exclude=pydoc_data --exclude=turtledemo --exclude=dist-packages --exclude=site-packages \
  --exclude='_tkinter*' --exclude='_dbm*' --exclude='_gdbm*' --exclude='_sqlite3*' python3.11 |
  tar -C "$D/python/lib" -xf -
for p in numpy open3d; do
  tar -C /usr/lib/python3/dist-packages -cf - --exclude=__pycache__ --exclude=tests --exclude=f2py \
    --exclude=distutils --exclude='_simd*' --exclude=examples "$p" |
    tar -C "$D/python/dist-packages" -xf -
done
# Every library the interpreter and the extension modules load, but the C
# and C++ runtimes.
find "$D" -name '*.so*' -o -name python3.11 | while read -r f; do ldd "$f" 2> /dev/null || true; done |
  awk '/=> \// {print $3}' | sort -u |
  grep -v -E '/(libc|libm|libpthread|libdl|librt|libutil|libresolv|ld-linux-x86-64|libstdc\+\+|libgcc_s)\.so' |
  while read -r lib; do cp -L "$lib" "$D/lib/"; done
cat > "$D/run.sh" <<'RUN'
#!/bin/sh
here=$(cd "$(dirname "$0")" && pwd)
export PYTHONHOME="$here/python" PYTHONPATH="$here/python/dist-packages" PYTHONDONTWRITEBYTECODE=1
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
exec "$here/python3.11" "$@"
RUN
chmod +x "$D/run.sh"
env -i "$D/run.sh" -c "import numpy, open3d; print('open3d', open3d.__version__, 'numpy', numpy.__version__)"
tar -C "$OUT" -cf - open3d | xz -9e -T0 > "$OUT/open3d.tar.xz"
du -sh "$D" "$OUT/open3d.tar.xz"
