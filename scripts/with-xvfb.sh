#!/bin/sh
# Runs a command that renders figures (a render test, or `parcelscope compare`)
# under a virtual X server of its own:  scripts/with-xvfb.sh COMMAND ARGS...
# Xvfb picks a free display number itself (-displayfd) and reports it once it
# accepts connections, so commands started in parallel never share or race for
# a display. Set PARCELSCOPE_USE_DISPLAY=1 to render on the current $DISPLAY
# instead. The command's exit status is returned.
if [ -n "${PARCELSCOPE_USE_DISPLAY:-}" ] && [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
if ! command -v Xvfb >/dev/null 2>&1; then
  echo "with-xvfb.sh: Xvfb not found (Debian package xvfb; scripts/install-deps.sh installs it)" >&2
  exit 1
fi
dir=$(mktemp -d "${TMPDIR:-/tmp}/parcelscope-xvfb.XXXXXX") || exit 1
Xvfb -displayfd 3 -screen 0 1920x1200x24 -nolisten tcp 3>"$dir/display" 2>"$dir/log" &
server=$!
stop() {
  kill "$server" 2>/dev/null
  wait "$server" 2>/dev/null
  rm -rf "$dir"
}
trap 'stop; exit 130' INT
trap 'stop; exit 143' TERM
# The number arrives with a newline once the server is ready (at most 30 s).
tries=0
until grep -q . "$dir/display" 2>/dev/null; do
  if ! kill -0 "$server" 2>/dev/null || [ "$tries" -ge 600 ]; then
    echo "with-xvfb.sh: Xvfb did not start:" >&2
    cat "$dir/log" >&2
    stop
    exit 1
  fi
  tries=$((tries + 1))
  sleep 0.05
done
DISPLAY=":$(head -n 1 "$dir/display")"
export DISPLAY
"$@"
status=$?
stop
exit "$status"
