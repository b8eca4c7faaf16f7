#!/usr/bin/env bash
# Run-time environment for Debian's OpenFOAM, without its interactive bashrc.
#
# OpenFOAM applications (Debian's blockMesh, pisoFoam, ... and ours: coredemFoamCheck,
# coredemFoam) only need to find the etc tree, which WM_PROJECT_DIR points at. Sourcing
# /usr/share/openfoam/etc/bashrc also works, but in a non-interactive shell it prints errors
# about the bin/ tools Debian does not ship and derives WM_PROJECT_USER_DIR from $USER.
#
#   source scripts/openfoam-env.sh            set the variables in this shell
#   scripts/openfoam-env.sh CMD [ARGS...]     run one command with them, e.g.
#   scripts/openfoam-env.sh blockMesh -case path/to/case
#
# Override the location with OPENFOAM_PROJECT_DIR=/path (a folder that has etc/controlDict).

_coredem_foam_dir=${OPENFOAM_PROJECT_DIR:-${WM_PROJECT_DIR:-/usr/share/openfoam}}
if [[ ! -f "$_coredem_foam_dir/etc/controlDict" ]]; then
  echo "openfoam-env: error: $_coredem_foam_dir/etc/controlDict not found; install Debian's" \
       "openfoam package (scripts/install-deps.sh) or set OPENFOAM_PROJECT_DIR" >&2
  if [[ "${BASH_SOURCE[0]}" != "$0" ]]; then return 1; else exit 1; fi
fi
export WM_PROJECT=OpenFOAM
export WM_PROJECT_DIR=$_coredem_foam_dir
unset _coredem_foam_dir

if [[ "${BASH_SOURCE[0]}" == "$0" ]]; then
  if [[ $# -eq 0 ]]; then
    echo "usage: source $0   or   $0 COMMAND [ARGS...]" >&2
    exit 1
  fi
  exec "$@"
fi
