#!/bin/sh
# Runs CMD ARGS... with an X display for ParaView's pvbatch (coredem render, the ParaView e2e
# tests): as it is when DISPLAY is set, else on a private virtual X server (Debian's Xvfb) that
# this script starts on a free display and stops afterwards. Exit status: CMD's, 3 when no X
# server can be had.
set -u
if [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
if ! command -v Xvfb >/dev/null 2>&1; then
  echo "with-xvfb: no DISPLAY and no Xvfb: install it (Debian: apt-get install xvfb)" >&2
  exit 3
fi
n=90
while [ -e "/tmp/.X$n-lock" ] || [ -e "/tmp/.X11-unix/X$n" ]; do
  n=$((n + 1))
done
# -noreset: pvbatch opens and closes a connection before its render window; an X server that
# resets when its last client leaves refuses the next one meanwhile ("bad X server connection",
# about one run in two on a loaded machine, also under xvfb-run).
Xvfb ":$n" -screen 0 1920x1200x24 -nolisten tcp -noreset >/dev/null 2>&1 &
xpid=$!
trap 'kill "$xpid" 2>/dev/null' EXIT
trap 'exit 130' INT TERM
i=0
while [ ! -e "/tmp/.X11-unix/X$n" ]; do
  i=$((i + 1))
  if [ "$i" -gt 400 ] || ! kill -0 "$xpid" 2>/dev/null; then
    echo "with-xvfb: Xvfb :$n did not start" >&2
    exit 3
  fi
  sleep 0.05
done
DISPLAY=":$n" "$@"
