#!/bin/sh
# Runs a render test (or its test listing) under a virtual X server of its own.
# The server number search starts from the process id, so that tests started
# in parallel do not race for the same number. Set PARCELSCOPE_USE_DISPLAY=1 to
# render on the current $DISPLAY instead.
if [ -n "${PARCELSCOPE_USE_DISPLAY:-}" ] && [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
exec xvfb-run -a -n $(( $$ % 800 + 100 )) -s "-screen 0 1920x1200x24" "$@"
