# Sourced by the scripts in this folder: installs what is missing from Debian's packages and builds the
# catkin package into build/ at the repository root. Idempotent and quick when everything is present.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/build"
# Debian's ROS lives in /usr; a pyenv python3 first on PATH lacks catkin_pkg.
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"

# Everything the build and the tests use, from Debian 12's own packages.
PACKAGES=(
  build-essential cmake python3
  catkin python3-catkin-pkg ros-message-generation ros-message-runtime
  libstd-msgs-dev libgeometry-msgs-dev ros-std-msgs ros-geometry-msgs
  libvisualization-msgs-dev ros-visualization-msgs libstd-srvs-dev ros-std-srvs
  libroscpp-dev libtf2-ros-dev libtf2-geometry-msgs-dev ros-tf2-msgs
  python3-rostest librostest-dev python3-roslaunch python3-rostopic python3-rosbag
  libeigen3-dev libyaml-cpp-dev libopenvdb-dev libassimp-dev libroslib-dev libembree-dev libpng-dev
  tetgen
  googletest libgtest-dev libbenchmark-dev
  pybind11-dev python3-dev python3-numpy python3-pytest
  python3-distributed python3-h5py python3-yaml python3-matplotlib
  clang libclang-rt-14-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libinteractive-markers-dev libdiagnostic-updater-dev libnodeletlib-dev libnodeletlib-tools pluginlib-dev
  liburdf-dev ros-robot-state-publisher python3-sensor-msgs libsensor-msgs-dev libimage-transport-dev
  libdepth-image-proc-dev
  rosbash python3-rospy python3-rosbag python3-rosservice python3-tf2-ros python3-std-srvs python3-geometry-msgs
  python3-visualization-msgs python3-diagnostic-msgs python3-rosgraph-msgs
  rviz xvfb libgl1-mesa-dri python3-pil
)
# What only the demo needs on top: rviz (already in PACKAGES for the rviz screenshot test).
DEMO_PACKAGES=(rviz)
# What scripts/demo builds: the node, the state viewer (play.launch), and all that a client of the running
# node needs from the build, the package's messages and services (C++, Python, Lisp) and its
# dynamic_reconfigure code (C++, Python): rostopic, rosservice, grasp_example.py and a user's own code
# (soft_body_sim.msg, .srv, .cfg, the C++ headers) load them. Not `all`, which adds the nodelet, the headless
# simulator, the benchmarks and the tests' main library (36 s more on two cores); the tests themselves are the
# `tests` target.
DEMO_TARGETS=(soft_body_sim_node state_viewer soft_body_sim_generate_messages soft_body_sim_gencfg)
# What only scripts/bench needs on top: Bullet (the peer; Debian builds it in double precision too, as
# pkg-config bullet-float64), pkg-config to find it, matplotlib for the plots.
BENCH_PACKAGES=(libbullet-dev pkg-config python3-matplotlib)

log() { printf '[%s] %s\n' "$(basename "$0")" "$*" >&2; }

# install_missing [EXTRA_PACKAGE...]: installs whatever of PACKAGES and the extras is missing.
install_missing() {
  local missing=() package
  for package in "${PACKAGES[@]}" "$@"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  log "installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
}

# Configures (once) and builds; the full output goes to build/build.log, shown when the build fails.
build_package() {
  mkdir -p "$BUILD"
  : >"$BUILD/build.log"
  if [ ! -f "$BUILD/Makefile" ]; then
    log "configuring into $BUILD"
    cmake -S "$ROOT" -B "$BUILD" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
      >>"$BUILD/build.log" 2>&1 || { cat "$BUILD/build.log" >&2; return 1; }
  fi
  log "building"
  make -C "$BUILD" -j"$(nproc)" "$@" >>"$BUILD/build.log" 2>&1 || { tail -n 60 "$BUILD/build.log" >&2; return 1; }
}
