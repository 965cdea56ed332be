#!/bin/sh
# Runs a command that renders figures (the render tests, the application under
# test) under a virtual X server of its own:  scripts/with-xvfb.sh COMMAND ARGS...
# (`parcelscope compare` needs no wrapper: without a display it starts a
# private Xvfb itself.)
# Xvfb picks a free display number itself (-displayfd) and reports it once it
# accepts connections, so commands started in parallel never share or race for
# a display. It listens on a local socket only, without an authorisation
# cookie (a helper for tests and headless figures). Set
# PARCELSCOPE_USE_DISPLAY=1 to render on the current $DISPLAY instead. The
# command's exit status is returned; the server is stopped however the script
# ends (a signal sent to this script alone takes effect once the command ends;
# Ctrl-C on a terminal reaches both).
if [ -n "${PARCELSCOPE_USE_DISPLAY:-}" ] && [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
if ! command -v Xvfb >/dev/null 2>&1; then
  echo "with-xvfb.sh: Xvfb not found (Debian package xvfb; scripts/install-deps.sh installs it)" >&2
  exit 1
fi
dir=$(mktemp -d "${TMPDIR:-/tmp}/parcelscope-xvfb.XXXXXX") || exit 1
server=
stop() {
  [ -n "$server" ] && kill "$server" 2>/dev/null && wait "$server" 2>/dev/null
  server=
  rm -rf "$dir"
}
trap stop EXIT
trap 'stop; exit 129' HUP
trap 'stop; exit 130' INT
trap 'stop; exit 131' QUIT
trap 'stop; exit 143' TERM
# -noreset: the server keeps going when its last client leaves (a program that
# opens and closes several windows would otherwise race the reset).
Xvfb -displayfd 3 -screen 0 1920x1200x24 -nolisten tcp -noreset 3>"$dir/display" </dev/null >/dev/null 2>"$dir/log" &
server=$!
# The number arrives with a newline once the server is ready (at most 30 s).
tries=0
until grep -q . "$dir/display" 2>/dev/null; do
  if ! kill -0 "$server" 2>/dev/null || [ "$tries" -ge 600 ]; then
    echo "with-xvfb.sh: Xvfb did not start:" >&2
    cat "$dir/log" >&2
    exit 1
  fi
  tries=$((tries + 1))
  sleep 0.05
done
DISPLAY=":$(head -n 1 "$dir/display")"
export DISPLAY
# In the foreground: Ctrl-C on a terminal reaches the command itself (which
# may clean up), and the traps above run once it has ended.
"$@"
