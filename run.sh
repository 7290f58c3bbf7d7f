#!/usr/bin/env bash
# Single entry point: set-up on a fresh Debian 12 or 13 machine (as root) + the two jobs.
#   bash run.sh demo [args...]   the main job: the flat-punch demo (demos/demo_flat_punch.py)
#   bash run.sh test             the test suite: unit tests, FE tests serial and on 2 ranks, demos
#   bash run.sh setup            only the set-up (idempotent, fast when done)
#   bash run.sh python ...       run a command with the project's interpreter and environment
#   bash run.sh test-debian13    the test suite inside a Debian 13 (DOLFINx 0.9) chroot, built
#                                once with mmdebstrap and cached in /var/cache/rough_contact/trixie
#   bash run.sh debian13 CMD ... any run.sh command (or `shell`) inside that chroot
# The set-up works on Debian 12 (DOLFINx 0.5.2) and Debian 13 (DOLFINx 0.9); what differs per
# release (pins of the optional extras) is in constraints/debian-<VERSION_ID>.txt.
# Optional extras (pyproject [project.optional-dependencies]) are installed when asked:
#   RC_EXTRAS=bem,topography bash run.sh setup
# The test command asks for the extras its tests need (TEST_EXTRAS below).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$here"

DEB_PACKAGES=(python3-dolfinx python3-gmsh python3-scipy python3-pytest python3-matplotlib
              python3-h5py python3-venv python3-wheel libopenblas0-pthread openmpi-bin)
# The Debian 13 chroot sets RC_VENV to a venv inside the chroot, so that the host's .venv (in the
# bind-mounted repository) is never touched.
VENV="${RC_VENV:-$here/.venv}"
TEST_EXTRAS="bem,topography"
PY="$VENV/bin/python"
# Debian release (12 = bookworm, DOLFINx 0.5.2; 13 = trixie, DOLFINx 0.9): selects the pins of
# the optional extras (constraints/debian-<VERSION_ID>.txt).
DEBIAN_VERSION="$(. /etc/os-release 2>/dev/null && echo "${VERSION_ID:-unknown}")" || DEBIAN_VERSION=unknown
# Debian 13 chroot for `test-debian13`/`debian13` (see debian13_run).
DEBIAN13_ROOT="${RC_DEBIAN13_ROOT:-/var/cache/rough_contact/trixie}"
DEBIAN13_REPO=/work/rough_contact           # where the repository is bind-mounted inside
DEBIAN13_VENV=/opt/rough_contact/venv       # the chroot's venv (inside the chroot, not the repo)

setup() {
    local missing=()
    local extras="${RC_EXTRAS:-}"
    if [ "$DEBIAN_VERSION" = 13 ] && [[ ",$extras," == *",bem,"* ]]; then
        # constraints/debian-13.txt says why: no importable tamaas wheel for Debian's Python 3.13.
        echo "[setup] extra 'bem' skipped on Debian 13 (tamaas has no wheel for Python 3.13" \
             "without free threading); rough_contact.micro.bem uses its numpy backend" >&2
        extras="$(echo ",$extras," | sed 's/,bem,/,/g; s/^,//; s/,$//')"
    fi
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
    # A venv made by another Python (e.g. the host's .venv seen from the Debian 13 chroot) would
    # import nothing: refuse it rather than delete it.
    local sys_ver venv_ver
    sys_ver="$(/usr/bin/python3 -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
    venv_ver="$(sed -n 's/^version *= *\([0-9]*\.[0-9]*\).*/\1/p' "$VENV/pyvenv.cfg" 2>/dev/null)"
    if [ -n "$venv_ver" ] && [ "$venv_ver" != "$sys_ver" ]; then
        echo "[setup] $VENV was made by Python $venv_ver, this system has $sys_ver:" \
             "remove it or set RC_VENV to another directory" >&2
        exit 1
    fi
    # Pin numpy/scipy to Debian's: a numpy wheel in the venv other than the one Debian's
    # petsc4py was built against breaks it ("numpy.dtype size changed"). The constraints file is
    # generated from the system versions, followed by the release's pins of the optional extras.
    local cons="$VENV/constraints.txt"
    local platform_cons="constraints/debian-$DEBIAN_VERSION.txt"
    {
        /usr/bin/python3 - <<'PYEOF'
import numpy, scipy
print(f"numpy=={numpy.__version__}\nscipy=={scipy.__version__}")
PYEOF
        if [ -f "$platform_cons" ]; then
            grep -v '^[[:space:]]*\(#\|$\)' "$platform_cons"
        else
            echo "[setup] no $platform_cons (Debian $DEBIAN_VERSION): extras unpinned" >&2
        fi
    } > "$cons.new"
    # Re-install when the pins change (another release's file, or the file edited).
    local stamp_cons="$VENV/.constraints-installed"
    cmp -s "$cons.new" "$stamp_cons" || rm -f "$VENV"/.installed*
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
        cp "$cons" "$stamp_cons"
    fi
}

# ---- Debian 13 (trixie, DOLFINx 0.9) in a chroot, from a Debian 12 host -------------------------
# The root file system is built once by mmdebstrap from Debian's packages (about 2 min, 2.7 GB)
# into a temporary directory and renamed into place, so an interrupted build is never taken for a
# cached one. Every run bind-mounts /proc, /sys, /dev, /dev/pts, /dev/shm and this repository
# (at $DEBIAN13_REPO) and unmounts them on exit, failure or interrupt included. Inside, the same
# `bash run.sh ...` does its set-up with Debian 13's packages and a venv in the chroot.
debian13_build() {
    [ -d "$DEBIAN13_ROOT" ] && return 0
    if ! command -v mmdebstrap > /dev/null; then
        echo "[debian13] installing mmdebstrap"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends mmdebstrap > /dev/null
    fi
    local include tmp t0=$SECONDS
    include="$(IFS=,; echo "${DEB_PACKAGES[*]},python3-pip,ca-certificates")"
    mkdir -p "$(dirname "$DEBIAN13_ROOT")"
    tmp="$(mktemp -d "$DEBIAN13_ROOT.tmp.XXXXXX")"
    echo "[debian13] building $DEBIAN13_ROOT with mmdebstrap (once; log: $tmp.log)"
    if ! mmdebstrap --variant=apt --include="$include" trixie "$tmp" > "$tmp.log" 2>&1; then
        tail -20 "$tmp.log" >&2
        rm -rf "$tmp"
        echo "[debian13] mmdebstrap failed (log kept: $tmp.log)" >&2
        exit 1
    fi
    mv -T "$tmp" "$DEBIAN13_ROOT"
    mv "$tmp.log" "$DEBIAN13_ROOT.build.log"
    echo "[debian13] root file system built in $((SECONDS - t0)) s"
}

DEBIAN13_MOUNTS=()
debian13_umount() {
    local i m
    for ((i = ${#DEBIAN13_MOUNTS[@]} - 1; i >= 0; i--)); do
        m="${DEBIAN13_MOUNTS[i]}"
        umount "$m" 2>/dev/null || umount -l "$m" 2>/dev/null || echo "[debian13] could not unmount $m" >&2
    done
    DEBIAN13_MOUNTS=()
}

debian13_run() {    # debian13_run CMD...: `bash run.sh CMD...` inside the chroot (CMD=shell: a shell)
    local t0=$SECONDS
    local root="$DEBIAN13_ROOT"
    [ "$(id -u)" -eq 0 ] || { echo "[debian13] building and entering the chroot needs root" >&2; exit 1; }
    # One build or run at a time per machine: the root file system and its mount points are shared.
    mkdir -p "$(dirname "$root")"
    exec 9> "$root.lock"
    flock -w 3600 9 || { echo "[debian13] another run holds $root.lock" >&2; exit 1; }
    debian13_build
    trap debian13_umount EXIT
    trap 'exit 130' INT
    trap 'exit 143' TERM
    local src dst
    for src in /proc /sys /dev /dev/pts /dev/shm "$here"; do
        dst="$root${src}"
        [ "$src" = "$here" ] && dst="$root$DEBIAN13_REPO"
        mkdir -p "$dst"
        mountpoint -q "$dst" && umount -l "$dst"      # left over by a killed run
        mount --bind "$src" "$dst"
        DEBIAN13_MOUNTS+=("$dst")
    done
    cp /etc/resolv.conf "$root/etc/resolv.conf"        # apt and pip reach the registries
    # The host's local certificate authorities (e.g. a network's TLS proxy) are trusted inside too.
    local crt changed=0
    for crt in /usr/local/share/ca-certificates/*.crt; do
        [ -f "$crt" ] || continue
        cmp -s "$crt" "$root$crt" || { mkdir -p "$root${crt%/*}"; cp "$crt" "$root$crt"; changed=1; }
    done
    [ $changed -eq 0 ] || chroot "$root" /usr/sbin/update-ca-certificates > /dev/null 2>&1
    local inner=(bash run.sh "$@")
    [ "${1:-}" = shell ] && inner=(bash -l)
    # A clean environment: only what the project reads is passed on.
    local envs=(HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
                LANG=C.UTF-8 TERM="${TERM:-dumb}" RC_VENV="$DEBIAN13_VENV")
    local v
    for v in CI RC_EXTRAS NP OPENBLAS_NUM_THREADS OMP_NUM_THREADS PYTEST_ADDOPTS PETSC_OPTIONS \
             OMPI_ALLOW_RUN_AS_ROOT OMPI_ALLOW_RUN_AS_ROOT_CONFIRM MPLBACKEND; do
        [ -z "${!v+x}" ] || envs+=("$v=${!v}")
    done
    echo "[debian13] chroot ready in $((SECONDS - t0)) s (Debian $(. "$root/etc/os-release" && echo "$VERSION_ID"))"
    local rc=0
    t0=$SECONDS
    chroot "$root" /usr/bin/env -i "${envs[@]}" bash -c 'cd "$0" && exec "$@"' \
        "$DEBIAN13_REPO" "${inner[@]}" || rc=$?
    debian13_umount
    echo "[debian13] \`bash run.sh $*\` in the chroot: $((SECONDS - t0)) s, exit $rc"
    return $rc
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
    test-debian13)
        debian13_run test "$@" ;;
    debian13)
        debian13_run "${@:-shell}" ;;
    *)
        echo "usage: bash run.sh {demo|test|setup|python|test-debian13|debian13} [args...]" >&2
        exit 2 ;;
esac
