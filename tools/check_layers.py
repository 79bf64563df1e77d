#!/usr/bin/env python3
"""The module graph of src/ has no cycle: each folder includes only the
folders below it (README "Architecture"). Reads every #include "folder/..."
of src/<folder>/*; exits 1 naming each include that points the wrong way,
or a folder this table does not know. Run by ctest (test `layers`)."""
import pathlib
import re
import sys

# Each folder and the src/ folders it may include (besides itself). The
# public headers (include/rthdist) are the contract every layer shares.
ALLOWED = {
    "core": set(),                                  # index space, input frame, parallel loop
    "cpu": {"core"},                                # the CPU backend
    "gpu": {"core"},                                # Vulkan plumbing
    "gpu_algo": {"gpu", "core"},                    # the GPU algorithm, by stage
    "api": {"gpu_algo", "gpu", "cpu", "core"},      # the public entry points
    "io": set(),                                    # loaders, beside the engine
    "render": {"gpu"},                              # the CLI's pictures
    "masks_gpu": {"gpu", "core"},                   # the masks' boundary pass (compute)
    "masks": {"masks_gpu", "core"},                 # segmentation masks, on the public API
    "mpi": {"core"},                                # MPI, on the public API
}

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent) / "src"
include = re.compile(r'^\s*#\s*include\s+"([a-z_]+)/')
problems = []
for folder in sorted(p for p in root.iterdir() if p.is_dir()):
    if folder.name not in ALLOWED:
        problems.append(f"src/{folder.name}: a folder the layer table (tools/check_layers.py) does not list")
        continue
    allowed = ALLOWED[folder.name] | {folder.name}
    for source in sorted(folder.rglob("*")):
        if source.suffix not in {".cpp", ".hpp", ".h"}:
            continue
        for number, line in enumerate(source.read_text().splitlines(), 1):
            m = include.match(line)
            if m and m.group(1) != "rthdist" and (root / m.group(1)).is_dir() and m.group(1) not in allowed:
                problems.append(f"{source.relative_to(root.parent)}:{number}: src/{folder.name} includes "
                                f"src/{m.group(1)} ({line.strip()}), which is not below it")
for p in problems:
    print(p)
print(f"layers: {len(problems)} problem(s)")
sys.exit(1 if problems else 0)
