#!/usr/bin/env bash
# Single entry point: set-up on a fresh Debian 12 machine (as root) + the two jobs.
#   bash run.sh demo [args...]   the main job: the flat-punch demo (demos/demo_flat_punch.py)
#   bash run.sh test             the test suite: unit tests, FE tests serial and on 2 ranks, demos
#   bash run.sh setup            only the set-up (idempotent, fast when done)
#   bash run.sh python ...       run a command with the project's interpreter and environment
# Optional extras (pyproject [project.optional-dependencies]) are installed when asked:
#   RC_EXTRAS=bem,topography bash run.sh setup
# The test command asks for the extras its tests need (TEST_EXTRAS below).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"

DEB_PACKAGES=(python3-dolfinx python3-gmsh python3-scipy python3-pytest python3-matplotlib
              python3-h5py python3-venv python3-wheel libopenblas0-pthread openmpi-bin)
VENV="$here/.venv"
TEST_EXTRAS="bem,topography"
PY="$VENV/bin/python"

setup() {
    local missing=()
    local extras="${RC_EXTRAS:-}"
    for p in "${DEB_PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if [ ${#missing[@]} -gt 0 ]; then
        echo "[setup] installing Debian packages: ${missing[*]}"
        local sudo=""
        [ "$(id -u)" -eq 0 ] || sudo="sudo"
        $sudo apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
    fi
    if [ ! -x "$PY" ]; then
        echo "[setup] creating virtual environment $VENV (with Debian's site packages)"
        /usr/bin/python3 -m venv --system-site-packages "$VENV"
    fi
    # Pin numpy/scipy to Debian's: a numpy 2 wheel in the venv breaks petsc4py
    # ("numpy.dtype size changed"). The constraints file is generated from the system versions.
    local cons="$VENV/constraints.txt"
    /usr/bin/python3 - > "$cons.new" <<'PYEOF'
import numpy, scipy
print(f"numpy=={numpy.__version__}\nscipy=={scipy.__version__}")
PYEOF
    mv "$cons.new" "$cons"
    local target="."
    [ -z "$extras" ] || target=".[$extras]"
    local stamp="$VENV/.installed${extras:+-${extras//,/-}}"
    if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
        echo "[setup] pip install -e $target (constraints: $(tr '\n' ' ' < "$cons"))"
        "$PY" -m pip install -q --no-build-isolation -c "$cons" -e "$target"
        # SurfaceTopography (extra "topography") pulls the PyPI h5py wheel, which bundles an HDF5
        # other than dolfinx's and fails ("Not a datatype") when imported after dolfinx: keep
        # Debian's python3-h5py (in DEB_PACKAGES) and remove the wheel from the venv.
        if [[ ",$extras," == *",topography,"* ]] && "$PY" -m pip show -q h5py 2>/dev/null; then
            "$PY" -m pip uninstall -y -q h5py
        fi
        touch "$stamp"
    fi
}

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# One BLAS thread per MPI rank: the machines have 2 cores.
export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}" OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"
export MPLBACKEND=Agg
# glibc returns large freed blocks to the OS and page-faults them again on the next call: the
# vectorised interface kernels allocate multi-MB temporaries per call, so keep them mapped
# (about 2x on the interface law, benchmarks/bench_interface_law.py).
export MALLOC_MMAP_THRESHOLD_="${MALLOC_MMAP_THRESHOLD_:-134217728}" MALLOC_TRIM_THRESHOLD_="${MALLOC_TRIM_THRESHOLD_:-536870912}"

# pytest exits 5 when it collects nothing (a directory without tests yet): not a failure.
run_pytest() {
    local rc=0
    "$@" || rc=$?
    [ $rc -eq 5 ] && rc=0
    return $rc
}

cmd="${1:-demo}"
shift || true
case "$cmd" in
    setup)
        setup ;;
    demo)
        setup
        if [ -f demos/demo_flat_punch.py ]; then
            exec mpirun -n "${NP:-2}" "$PY" demos/demo_flat_punch.py "$@"
        else
            exec "$PY" demos/demo_micro_model.py "$@"
        fi ;;
    test)
        RC_EXTRAS="${RC_EXTRAS:-$TEST_EXTRAS}" setup
        echo "== unit tests (pure numpy) =="
        run_pytest "$PY" -m pytest -q --color=no tests/unit
        if compgen -G "tests/fem/test_*.py" > /dev/null; then
            echo "== FE tests, serial =="
            run_pytest "$PY" -m pytest -q --color=no tests/fem
            echo "== FE tests, mpirun -n 2 =="
            run_pytest mpirun -n 2 "$PY" -m mpi4py -m pytest -q --color=no -p no:cacheprovider tests/fem
        fi
        echo "== demos, run as scripts at a small size =="
        run_pytest "$PY" -m pytest -q --color=no tests/demos ;;
    python)
        setup
        exec "$PY" "$@" ;;
    *)
        echo "usage: bash run.sh {demo|test|setup|python} [args...]" >&2
        exit 2 ;;
esac
