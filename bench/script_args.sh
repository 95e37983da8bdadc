# Argument checks shared by the bench/*.sh comparison scripts (sourced, not run).

# Prints the calling script's usage (its comment, lines 2-8) and exits 2 when it got fewer than `needed`
# arguments: usage_unless GIVEN NEEDED.
usage_unless() {
    if [ "$1" -lt "$2" ]; then
        sed -n '2,8p' "$0" >&2
        exit 2
    fi
}

# Exits 2 naming the first argument that is not an executable file.
require_executables() {
    for bin in "$@"; do
        [ -x "$bin" ] || { echo "$(basename "$0"): $bin is not an executable" >&2; exit 2; }
    done
}
