# Shared settings for the build, test and demo scripts (sourced, not run).
# The catkin workspace lives in a git-ignored folder (ws/) whose src/fdml_localization links
# to this checkout's files, so the checkout itself stays the package's source tree.
REPO_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="${WS:-$REPO_DIR/ws}"
JOBS="${JOBS:-$(nproc)}"
# ROS tools run under the first python3 on PATH; Debian's has the ROS modules (rospkg, ...).
export PATH="/usr/bin:$PATH"
export ROS_HOME="${ROS_HOME:-$WS/ros_home}"
export ROS_LOG_DIR="${ROS_LOG_DIR:-$ROS_HOME/log}"

make_workspace() {
  # The package folder holds a link to each top-level entry of this checkout, except the
  # workspace itself: a link to the whole checkout would contain ws/ again, and roslaunch's
  # file search (which follows links) would loop through ws/src/fdml_localization/ws/...
  local pkg="$WS/src/fdml_localization"
  [ -L "$pkg" ] && rm "$pkg"
  mkdir -p "$pkg"
  local ws_real entry
  ws_real="$(cd "$WS" && pwd -P)"
  for entry in "$REPO_DIR"/*; do
    [ "$(cd "$entry" 2>/dev/null && pwd -P)" = "$ws_real" ] && continue
    case "$(basename "$entry")" in ws | ws-*) continue ;; esac  # other workspaces (ws-asan)
    ln -sfn "$entry" "$pkg/$(basename "$entry")"
  done
  find "$pkg" -maxdepth 1 -xtype l -delete  # entries removed from the checkout
}

catkin_build() {
  make_workspace
  # ccache, where installed, shares objects between checkouts (paths relative to the parent).
  local launcher=()
  if command -v ccache >/dev/null 2>&1; then
    export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(dirname "$REPO_DIR")}"
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  fi
  (cd "$WS" && catkin_make -j"$JOBS" "${launcher[@]}" \
      -DCMAKE_BUILD_TYPE=Release \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 \
      -DCATKIN_ENABLE_TESTING=ON "$@")
}

source_workspace() {
  # shellcheck disable=SC1091
  set +u
  source "$WS/devel/setup.bash"
  set -u
}

# start_simulation PORT LOG [roslaunch args...]: launches simulation.launch with its own master
# on PORT (output to LOG), stops it when the calling script exits, and waits up to 30 s for the
# master. Returns non-zero, with the end of LOG on stderr, when the simulation did not start.
start_simulation() {
  local port="$1" log="$2"
  shift 2
  export ROS_MASTER_URI="http://localhost:$port"
  export ROS_IP=127.0.0.1
  roslaunch -p "$port" fdml_localization simulation.launch "$@" >"$log" 2>&1 &
  SIMULATION_PID=$!
  trap 'kill -INT "$SIMULATION_PID" 2>/dev/null || true; wait "$SIMULATION_PID" 2>/dev/null || true' EXIT
  for _ in $(seq 300); do
    rosnode list >/dev/null 2>&1 && return 0
    kill -0 "$SIMULATION_PID" 2>/dev/null || break
    sleep 0.1
  done
  echo "the simulation did not start; the end of $log:" >&2
  tail -n 30 "$log" >&2
  return 1
}
