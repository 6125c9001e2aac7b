# Recipes of the openral monorepo. Run them through ./bootstrap on a fresh machine
# (it installs uv, just and the locked .venv first), or with `just` once set up.

set shell := ["bash", "-euo", "pipefail", "-c"]

export PATH := justfile_directory() + "/.venv/bin:" + env_var("PATH")
export MUJOCO_GL := env_var_or_default("MUJOCO_GL", "egl")
# Python caches the bytecode of what it imports (__pycache__); a machine that sets
# PYTHONDONTWRITEBYTECODE makes every process compile its imports again (`openral ros
# topics --help`: 1.4 s instead of 0.55 s), and the suite starts several hundred of them.
export PYTHONDONTWRITEBYTECODE := ""

# List the recipes.
default:
    @just --list

# The main job's command; `./bootstrap demo` execs it directly, so a signal to that PID reaches it.
demo_command := "openral deploy sim --config robots/franka_panda/scenes/tabletop.yaml --no-viewer"
test_workers := `python3 -c "import os; print(len(os.sched_getaffinity(0)) + 1)"`

# The main job: the Panda's default scene as a live ROS 2 graph, headless, until Ctrl-C.
demo:
    {{demo_command}}

# The whole test suite: first every test file but the real-time measurements, spread over
# one worker more than there are cores (pytest-xdist; each worker claims its own ROS domain:
# a third of a worker's time is spent waiting on live graphs, so a spare worker keeps the
# cores busy), then the measurements (marked `exclusive`) in one process, alone. Extra
# arguments go to both runs; the second may find none of its tests among them (pytest's
# exit status 5). Both runs share one folder of compiled models (tests/conftest.py).
test *ARGS:
    #!/usr/bin/env bash
    set -euo pipefail
    OPENRAL_TEST_MODEL_CACHE="$(mktemp -d -t openral-test-models-XXXXXX)"
    export OPENRAL_TEST_MODEL_CACHE
    trap 'rm -rf "$OPENRAL_TEST_MODEL_CACHE"' EXIT
    pytest -n {{test_workers}} --dist loadfile -m "not exclusive" {{ARGS}}
    pytest -m exclusive {{ARGS}} || [ $? -eq 5 ]

# ruff lint and format check.
lint:
    ruff check libs apps tests benchmarks
    ruff format --check libs apps tests benchmarks

# mypy --strict on the handwritten libraries and apps.
typecheck:
    mypy

# Regenerate generated/ and docs/reference/ from schema/ and robots/.
schema-export:
    python -m openral_codegen export

# Fail when `just schema-export` would change, add or remove a file.
schema-check:
    python -m openral_codegen check

# Build the docs site strictly into site/ (a warning, broken link or missing picture fails).
docs:
    NO_MKDOCS_2_WARNING=1 mkdocs build --strict --site-dir site

# Serve the docs site with live reload on http://127.0.0.1:8000.
docs-serve:
    NO_MKDOCS_2_WARNING=1 mkdocs serve

# Render the robot pictures of the docs (all robots, or the ids given) offscreen.
docs-images *IDS:
    python -m openral_codegen images {{IDS}}

# Retake docs/images/browser-view.png: `sim run --view` photographed in headless Chromium.
docs-view-image:
    python -m tests.docs.view_screenshot docs/images/browser-view.png

# Redraw the evaluation guide's sweep pictures from the videos of a scripted_lift sweep.
docs-sweep-images:
    python -m tests.docs.sweep_pictures

# Fuzz manifests and scenes through load, robot check and the HAL: N cases, counts by outcome, reproducers in fuzz-findings/.
fuzz N *ARGS:
    python -m tests.fuzz.campaign {{N}} {{ARGS}}

# The import layers (core -> mujoco -> sim -> hal -> bridge | eval -> apps), as pyproject.toml declares them.
layers:
    lint-imports --no-cache

# The static checks CI runs after the tests: lint, types, import layers, generated-tree drift.
check: lint typecheck layers schema-check

# The gymnasium env's step against the scene's own, and a vector env of 2 against one env.
bench-env *ARGS:
    python -m benchmarks.env_step {{ARGS}}

# End-effector actions on the Panda: IK cost per tick and how the TCP follows 1 cm steps.
bench-ik *ARGS:
    python -m benchmarks.ee_ik {{ARGS}}

# HAL overhead per robot against a raw mj_step loop; writes benchmarks/results/hal_step.json.
bench-hal *ARGS:
    python -m benchmarks.hal_step {{ARGS}}

# Native franka tabletop against robosuite Lift through SimAttachedHAL; writes benchmarks/results/scene_step.json.
bench-scene *ARGS:
    python -m benchmarks.scene_step {{ARGS}}

# deploy sim start-up (median of 5: first state, first sensor messages), stream rates and CPU, on the franka tabletop and the mobile room; writes benchmarks/results/deploy_startup*.json.
bench-deploy *ARGS:
    python -m benchmarks.deploy_startup {{ARGS}}

# deploy sim's camera path: CPU against a bare MuJoCo loop per image size, highest camera rate sustained; writes benchmarks/results/camera_path.json.
bench-camera *ARGS:
    python -m benchmarks.camera_path {{ARGS}}

# deploy sim against the wall clock: simulated/wall time, /joint_states and per-camera rates idle, under rskill at 10 and 40 Hz and a flood; writes benchmarks/results/real_time.json.
bench-realtime *ARGS:
    python -m benchmarks.real_time {{ARGS}}

# Sweep scaling: the franka tabletop sweeps with --workers 1, --workers 2 and --ray (2 CPUs): start-up, episodes and end-to-end times, speed-ups, identical results; writes benchmarks/results/sweep_scaling.json.
bench-sweep *ARGS:
    python -m benchmarks.sweep_scaling {{ARGS}}

# A manifest load and a HAL connect, the second time in one process, against the same with the in-process memories cleared; writes benchmarks/results/reload_cost.json.
bench-reload *ARGS:
    python -m benchmarks.reload_cost {{ARGS}}

# Joint-trajectory tracking on the franka tabletop: error against the path with and without the glide, and a following tick's cost over a holding one; writes benchmarks/results/trajectory_tracking.json.
bench-trajectory *ARGS:
    python -m benchmarks.trajectory_tracking {{ARGS}}

# The real driver on the emulated so101 bus: a control tick's bus round trip (against the bare SDK and the wire time) and 100 Hz held for 60 s; writes benchmarks/results/real_bus.json.
bench-real *ARGS:
    python -m benchmarks.real_bus {{ARGS}}

# deploy real on a ros2_control driver (deploy sim as the robot): a policy action to the driver's command, against one DDS hop; writes benchmarks/results/ros2_control_latency.json.
bench-ros2-control *ARGS:
    python -m benchmarks.ros2_control_latency {{ARGS}}

# CPU that `deploy sim --record` adds to deploy sim alone on the franka tabletop, and messages dropped; writes benchmarks/results/record_cost.json.
bench-record *ARGS:
    python -m benchmarks.record_cost {{ARGS}}

# Re-resolve every dependency and write requirements.lock (names, versions, hashes; no addresses). uv.lock is uv's working file, not committed.
lock:
    {{justfile_directory()}}/.tools/venv/bin/uv lock --quiet
    {{justfile_directory()}}/.tools/venv/bin/uv export --frozen --all-extras --all-groups --format requirements-txt --no-emit-project --no-header --quiet -o requirements.lock
