#!/usr/bin/env bash
# Prepares the OpenFOAM headers an application build needs, for the installed Debian `openfoam`.
#
# Debian's `openfoam` / `libopenfoam` packages ship the libraries (/usr/lib) and the etc tree
# (/usr/share/openfoam/etc) but no headers. This script downloads Debian's *source* package of
# exactly the installed version through a private apt configuration (the system's apt
# configuration and state are never changed), extracts only the parts an application needs,
# applies Debian's patches that touch them, and creates OpenFOAM's `lnInclude` trees.
#
# Usage: scripts/openfoam-headers.sh [--keep-download] [--force] CACHE_DIR
#   CACHE_DIR        where the tree goes; afterwards CACHE_DIR/src/<lib>/lnInclude exist
#   --keep-download  keep the downloaded source archives and apt lists (default: removed)
#   --force          redo everything even if the stamp says the cache is complete
#
# The cache is complete when CACHE_DIR/openfoam-headers.stamp names the installed version
# and the same component list; a second run is then a no-op. Works as root and as a normal
# user (apt-get with a private state directory needs no privileges).
#
# Exit codes: 0 done (or already done), 1 usage or unexpected error, 2 openfoam not installed,
# 3 download failed (network / source archive unreachable), 4 version mismatch.
set -euo pipefail

script_name=openfoam-headers
say() { echo "${script_name}: $*"; }
die() {
  local code=$1
  shift
  echo "${script_name}: error: $*" >&2
  exit "$code"
}

# The parts of the OpenFOAM source tree that applications in cfd-adapter/openfoam compile
# against. Keep in step with the include directories of coredem::openfoam
# (cmake/CoredemOpenFOAM.cmake). Each one must have a matching library in /usr/lib.
#   OpenFOAM, OSspecific/POSIX, finiteVolume, meshTools    core (icoFoam level)
#   fvOptions                                              libfvOptions (sources/constraints)
#   sampling                                               libsampling (probes, sampled sets)
#   transportModels/incompressible                         singlePhaseTransportModel
#   TurbulenceModels/{turbulenceModels,incompressible}     incompressible turbulence
#   TurbulenceModels/phaseIncompressible                   volume-fraction weighted turbulence
#                                                          (DPMFoam style, libDPMTurbulenceModels)
#   thermophysicalModels/{specie,basic,reactionThermo},    the ideal-gas mixture of coredemFoam's
#   transportModels/compressible                           variable-density gas (libspecie,
#                                                          libfluidThermophysicalModels,
#                                                          libreactionThermophysicalModels)
lnInclude_dirs=(
  src/OpenFOAM
  src/OSspecific/POSIX
  src/finiteVolume
  src/meshTools
  src/fvOptions
  src/sampling
  src/transportModels/incompressible
  src/TurbulenceModels/turbulenceModels
  src/TurbulenceModels/incompressible
  src/TurbulenceModels/phaseIncompressible
  src/thermophysicalModels/specie
  src/thermophysicalModels/basic
  src/thermophysicalModels/reactionThermo
  src/transportModels/compressible
)
extract_paths=(META-INFO wmake "${lnInclude_dirs[@]}")

keep_download=false
force=false
cache_dir=
while [[ $# -gt 0 ]]; do
  case "$1" in
    --keep-download) keep_download=true ;;
    --force) force=true ;;
    -h | --help)
      sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
      exit 0
      ;;
    -*) die 1 "unknown option '$1' (see --help)" ;;
    *)
      [[ -z "$cache_dir" ]] || die 1 "only one CACHE_DIR may be given (got '$cache_dir' and '$1')"
      cache_dir=$1
      ;;
  esac
  shift
done
[[ -n "$cache_dir" ]] || die 1 "missing CACHE_DIR. Usage: $0 [--keep-download] [--force] CACHE_DIR"

# --- 1. What is installed ---------------------------------------------------------------------
if ! dpkg-query -W -f='${Status}' openfoam 2>/dev/null | grep -q "install ok installed"; then
  die 2 "Debian's 'openfoam' package is not installed, so there is no version to fetch headers for. Install it with: apt-get install openfoam   (or scripts/install-deps.sh)"
fi
bin_version=$(dpkg-query -W -f='${Version}' openfoam)
src_version=$(dpkg-query -W -f='${source:Version}' openfoam)
src_package=$(dpkg-query -W -f='${source:Package}' openfoam)
api=${src_version%%.*}
[[ "$api" =~ ^[0-9]{4}$ ]] ||
  die 4 "cannot read the OpenFOAM API number from the source version '$src_version' of package openfoam"
for lib in libOpenFOAM.so libfiniteVolume.so libmeshTools.so; do
  [[ -e /usr/lib/$lib ]] ||
    die 2 "/usr/lib/$lib is missing although openfoam $bin_version is installed. Reinstall it: apt-get install --reinstall libopenfoam"
done

mkdir -p "$cache_dir"
cache_dir=$(cd "$cache_dir" && pwd -P)
stamp="$cache_dir/openfoam-headers.stamp"
stamp_text="package=$src_package
version=$src_version
binary_version=$bin_version
api=$api
components=${lnInclude_dirs[*]}"

# One preparation at a time per cache (two configure runs may share a build tree).
exec 9>"$cache_dir/.lock"
if ! flock -w 900 9; then
  die 1 "another openfoam-headers run holds $cache_dir/.lock for more than 15 minutes; if none is running, delete that file"
fi

if [[ "$force" == false && -f "$stamp" ]] && diff -q <(echo "$stamp_text") <(grep -v '^prepared=' "$stamp") >/dev/null; then
  touch "$stamp" # lets CMake see the cache as newer than this script and skip calling it
  say "OpenFOAM $src_version headers are ready in $cache_dir (stamp present, nothing to do)"
  exit 0
fi

start_s=$(date +%s)
say "preparing the headers of $src_package $src_version (installed binary: $bin_version, API $api) in $cache_dir"
rm -f "$stamp"

# --- 2. Private apt configuration derived from the system's sources ------------------------------
apt_dir="$cache_dir/apt"
rm -rf "$apt_dir"
mkdir -p "$apt_dir/sources.list.d" "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial"

# Only the system's Debian-format entries are copied, with their type turned into deb-src.
n_entries=0
shopt -s nullglob
for f in /etc/apt/sources.list.d/*.sources; do
  # deb822: every stanza's "Types:" becomes "Types: deb-src"; everything else is kept.
  sed -E 's/^Types:.*/Types: deb-src/I' "$f" >"$apt_dir/sources.list.d/$(basename "$f")"
  n=$(grep -ciE '^Types:' "$f" || true)
  n_entries=$((n_entries + n))
done
for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
  [[ -f "$f" ]] || continue
  out="$apt_dir/sources.list.d/$(basename "$f" | sed 's/^sources\.list$/system.list/')"
  # one-line format: "deb [opts] uri suite comp..." -> "deb-src [opts] uri suite comp..."
  grep -E '^[[:space:]]*deb(-src)?[[:space:]]' "$f" | sed -E 's/^[[:space:]]*deb(-src)?[[:space:]]/deb-src /' |
    sort -u >"$out" || true
  n=$(wc -l <"$out")
  n_entries=$((n_entries + n))
done
shopt -u nullglob
[[ $n_entries -gt 0 ]] ||
  die 3 "the system has no apt sources (/etc/apt/sources.list.d/*.sources or sources.list) to derive Debian's source archive from"

cat >"$apt_dir/apt.conf" <<EOF
// Private apt configuration of scripts/openfoam-headers.sh: the system's sources as deb-src,
// with lists and caches under this folder. The system's apt state is not touched.
Dir::Etc::SourceList "/dev/null";
Dir::Etc::SourceParts "$apt_dir/sources.list.d";
Dir::State::Lists "$apt_dir/lists";
Dir::Cache "$apt_dir/cache";
Dir::Cache::pkgcache "";
Dir::Cache::srcpkgcache "";
APT::Sandbox::User "$(id -un)";
Acquire::Languages "none";
Acquire::PDiffs "false";
Acquire::Retries "2";
Acquire::http::Timeout "30";
Acquire::https::Timeout "30";
EOF
export APT_CONFIG="$apt_dir/apt.conf"
# apt reads APT_CONFIG before the system's apt.conf.d (kept: it may hold the proxy or mirror
# settings this machine needs), so the private locations are repeated on the command line,
# which nothing in a configuration file can override.
apt_opts=(
  -o "Dir::Etc::SourceList=/dev/null"
  -o "Dir::Etc::SourceParts=$apt_dir/sources.list.d"
  -o "Dir::State::Lists=$apt_dir/lists"
  -o "Dir::Cache=$apt_dir/cache"
  -o "APT::Sandbox::User=$(id -un)"
)

say "apt-get update (private lists, $n_entries source entries as deb-src)"
t0=$(date +%s)
update_ok=true
if ! timeout 600 apt-get -q "${apt_opts[@]}" update >"$apt_dir/update.log" 2>&1; then
  update_ok=false
  say "warning: apt-get update reported errors (see $apt_dir/update.log); trying the download anyway"
fi
t_update=$(($(date +%s) - t0))
if ! compgen -G "$apt_dir/lists/*_Sources*" >/dev/null; then
  grep -E '^(W|E):' "$apt_dir/update.log" | head -n 5 >&2 || true
  die 3 "could not fetch any source index from the system's apt sources (no network, a proxy that is not configured, or the Debian mirror is unreachable). Log: $apt_dir/update.log. Without network, configure with -DCOREDEM_OPENFOAM=OFF."
fi

# --- 3. Download the source package of exactly the installed version ---------------------------
dl_dir="$cache_dir/download"
mkdir -p "$dl_dir"
say "apt-get source --download-only $src_package=$src_version"
t0=$(date +%s)
if ! (cd "$dl_dir" && timeout 900 apt-get -q "${apt_opts[@]}" source --download-only "$src_package=$src_version") >"$apt_dir/source.log" 2>&1; then
  if grep -qE "Can not find version|Unable to find a source package" "$apt_dir/source.log"; then
    available=$(apt-cache "${apt_opts[@]}" showsrc "$src_package" 2>/dev/null | sed -n 's/^Version: //p' | sort -u | tr '\n' ' ')
    if [[ -n "$available" ]]; then
      die 4 "Debian's source archive has $src_package version(s) [ ${available}] but not the installed $src_version. Install a matching binary (apt-get install openfoam=<one of those>) or configure with -DCOREDEM_OPENFOAM=OFF."
    fi
  fi
  tail -n 5 "$apt_dir/update.log" "$apt_dir/source.log" >&2 || true
  if [[ "$update_ok" == false ]]; then
    die 3 "could not download Debian's source package $src_package $src_version: the source indexes could not be fetched (no network, or the Debian mirror in the system's apt sources is unreachable). Logs: $apt_dir/update.log, $apt_dir/source.log"
  fi
  die 3 "apt-get source $src_package=$src_version failed (log: $apt_dir/source.log)"
fi
t_download=$(($(date +%s) - t0))

first_file() { find "$dl_dir" -maxdepth 1 -name "$1" -print -quit; }
dsc=$(first_file "${src_package}_*.dsc")
[[ -n "$dsc" ]] || die 3 "apt-get source reported success but left no .dsc in $dl_dir"
dsc_version=$(sed -n 's/^Version: //p' "$dsc" | head -n 1)
[[ "$dsc_version" == "$src_version" ]] ||
  die 4 "downloaded $dsc has version '$dsc_version', the installed package needs '$src_version'"
orig=$(first_file "${src_package}_*.orig.tar.*")
debian_tar=$(first_file "${src_package}_*.debian.tar.*")
[[ -n "$orig" && -n "$debian_tar" ]] ||
  die 3 "expected ${src_package}_*.orig.tar.* and ${src_package}_*.debian.tar.* in $dl_dir (a 3.0 (quilt) source package)"
say "downloaded $(basename "$orig") ($(du -m "$orig" | cut -f1) MB) in ${t_download}s (index update ${t_update}s)"

# --- 4. Extract only what an application build needs --------------------------------------------
t0=$(date +%s)
rm -rf "$cache_dir/src" "$cache_dir/wmake" "$cache_dir/META-INFO" "$cache_dir/debian"
top=$(tar -tf "$orig" 2>/dev/null | head -n 1 || true)
top=${top%%/*}
[[ -n "$top" ]] || die 1 "cannot list $orig (corrupt download? rerun with --force)"
members=()
for p in "${extract_paths[@]}"; do members+=("$top/$p"); done
say "extracting ${extract_paths[*]}"
tar -xf "$orig" -C "$cache_dir" --strip-components=1 "${members[@]}" ||
  die 1 "extracting ${members[*]} from $orig failed"
tar -xf "$debian_tar" -C "$cache_dir" debian/patches debian/rules 2>/dev/null ||
  tar -xf "$debian_tar" -C "$cache_dir" debian/rules
t_extract=$(($(date +%s) - t0))

tree_api=$(sed -n 's/^api=//p' "$cache_dir/META-INFO/api-info" 2>/dev/null || true)
[[ "$tree_api" == "$api" ]] ||
  die 4 "the source tree says api=$tree_api but the installed openfoam $src_version is API $api"

# --- 5. Debian's patches, file by file, where they touch the extracted tree ----------------------
series="$cache_dir/debian/patches/series"
if [[ -f "$series" ]]; then
  split_dir="$cache_dir/debian/split"
  while read -r patch_name _; do
    [[ -n "$patch_name" && "$patch_name" != \#* ]] || continue
    patch_file="$cache_dir/debian/patches/$patch_name"
    rm -rf "$split_dir" && mkdir -p "$split_dir"
    # Split the patch into one chunk per file (a chunk starts at "--- a" followed by "+++ b").
    awk -v dir="$split_dir" '
      { lines[NR] = $0 }
      END {
        n = 0; out = ""
        for (i = 1; i <= NR; i++) {
          if (lines[i] ~ /^--- / && (i + 1) <= NR && lines[i + 1] ~ /^\+\+\+ /) {
            path = lines[i + 1]; sub(/^\+\+\+ [^\/]*\//, "", path); sub(/[ \t].*$/, "", path)
            n++; out = sprintf("%s/%03d", dir, n); print path > (out ".path"); close(out ".path")
          }
          if (out != "") print lines[i] > (out ".diff")
        }
      }' "$patch_file"
    applied=() skipped=()
    for chunk in "$split_dir"/*.diff; do
      [[ -e "$chunk" ]] || continue
      target=$(cat "${chunk%.diff}.path")
      if [[ -e "$cache_dir/$target" ]]; then
        patch -s -p1 -d "$cache_dir" --forward --batch <"$chunk" >/dev/null ||
          die 1 "Debian patch $patch_name does not apply to $target"
        applied+=("$target")
      else
        skipped+=("$target")
      fi
    done
    say "debian patch $patch_name: applied to ${#applied[@]} extracted file(s) ${applied[*]:-}; ${#skipped[@]} file(s) outside the extracted tree"
  done <"$series"
  rm -rf "$split_dir"
else
  say "debian tarball has no patches/series: nothing to apply"
fi

# --- 6. lnInclude trees ----------------------------------------------------------------------
t0=$(date +%s)
export WM_ARCH=linux64
for d in "${lnInclude_dirs[@]}"; do
  [[ -d "$cache_dir/$d" ]] || die 1 "$d is not in $(basename "$orig"); the component list does not fit this OpenFOAM version"
  (cd "$cache_dir" && ./wmake/wmakeLnInclude -u "$d" 2>&1 | sed "s/^/${script_name}:   /")
  [[ -d "$cache_dir/$d/lnInclude" ]] || die 1 "wmakeLnInclude did not create $d/lnInclude"
done
n_links=$(find "$cache_dir/src" -path '*/lnInclude/*' -type l | wc -l)
t_lninclude=$(($(date +%s) - t0))
[[ -e "$cache_dir/src/OpenFOAM/lnInclude/fvCFD.H" || -e "$cache_dir/src/finiteVolume/lnInclude/fvCFD.H" ]] ||
  die 1 "fvCFD.H is missing from the lnInclude trees; the extraction is incomplete"

if [[ "$keep_download" == false ]]; then
  rm -rf "$dl_dir" "$apt_dir/lists" "$apt_dir/cache"
fi

total=$(($(date +%s) - start_s))
{
  echo "$stamp_text"
  echo "prepared=$(date -u +%Y-%m-%dT%H:%M:%SZ) update=${t_update}s download=${t_download}s extract=${t_extract}s lnInclude=${t_lninclude}s total=${total}s"
} >"$stamp"
say "done in ${total}s (update ${t_update}s, download ${t_download}s, extract ${t_extract}s, lnInclude ${t_lninclude}s): $n_links header links in ${#lnInclude_dirs[@]} lnInclude trees, $(du -sm "$cache_dir" | cut -f1) MB"
