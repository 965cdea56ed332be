#!/bin/sh
# Runs a command that renders figures (a render test, or `parcelscope compare`)
# under a virtual X server of its own:  scripts/with-xvfb.sh COMMAND ARGS...
# The server number search starts from the process id, so that commands
# started in parallel do not race for the same number. Set
# PARCELSCOPE_USE_DISPLAY=1 to render on the current $DISPLAY instead.
if [ -n "${PARCELSCOPE_USE_DISPLAY:-}" ] && [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
exec xvfb-run -a -n $(( $$ % 800 + 100 )) -s "-screen 0 1920x1200x24" "$@"
