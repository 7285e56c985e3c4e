#!/usr/bin/env bash
# End to end, `serve` as scripts drive it: started, its URL read from stdout, stopped with TERM or INT. A stop
# must end it promptly at any moment: while it reads its scans (the process ends as by the signal) and from the
# instant its URL is printed (it stops serving and exits 0). Also the huge-page restart every command makes
# (cli/main.cc), seen in a running serve's environment.
# Run by ctest as `serve_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"

start_serve() {  # start_serve [VAR=VALUE ...] -- ARGS...: starts serve in the background; sets serve_pid
  local environment=()
  while [ "$1" != "--" ]; do
    environment+=("$1")
    shift
  done
  shift
  : >"$work/serve.out"
  env "${environment[@]}" "$lidarshop" serve --port 0 --token t "$@" >"$work/serve.out" 2>"$work/serve.err" &
  serve_pid=$!
}

wait_for_url() {  # wait_for_url: until serve printed its URL (30 s at most)
  for _ in $(seq 300); do
    grep -q "^http" "$work/serve.out" && return 0
    sleep 0.1
  done
  return 1
}

stop_serve() {  # stop_serve SIGNAL: sends it; fails when serve has not ended 5 s later (then KILLs it)
  kill "-$1" "$serve_pid" 2>/dev/null
  for _ in $(seq 50); do
    if ! kill -0 "$serve_pid" 2>/dev/null; then
      wait "$serve_pid"
      serve_status=$?
      return 0
    fi
    sleep 0.1
  done
  kill -KILL "$serve_pid" 2>/dev/null
  wait "$serve_pid" 2>/dev/null
  echo "serve did not end within 5 s of $1" >&2
  return 1
}

# A stop right after the URL (the moment a script first may): an earlier serve installed its handlers after
# printing the URL and missed a stop that came before it listened, and ran for ever.
stopped_right_after_url() {  # stopped_right_after_url SIGNAL TIMES
  for _ in $(seq "$2"); do
    start_serve -- || return 1
    wait_for_url || {
      stop_serve KILL
      return 1
    }
    stop_serve "$1" || return 1
    [ "$serve_status" -eq 0 ] || {
      echo "exit $serve_status after $1 once serving" >&2
      return 1
    }
  done
}
check "TERM right after the URL stops serve (20 times)" stopped_right_after_url TERM 20
check "INT right after the URL stops serve (10 times)" stopped_right_after_url INT 10

# A stop while serve reads the scans it was given (twelve built-in parking lots, scanned first: about 1.5 s):
# the process ends as by the signal, before printing any URL.
stopped_while_reading() {
  local scenes=()
  for _ in $(seq 12); do scenes+=(--scene parking_lot); done
  start_serve -- "${scenes[@]}"
  sleep 0.3
  grep -q "^http" "$work/serve.out" && {
    echo "the scene was read within 0.3 s: the check cannot stop serve while it reads" >&2
    stop_serve TERM
    return 1
  }
  stop_serve TERM || return 1
  [ "$serve_status" -eq 143 ] || {
    echo "exit $serve_status after TERM while reading (expected 143)" >&2
    return 1
  }
}
check "TERM while reading ends serve" stopped_while_reading

# The CLI restarts itself once with glibc's huge-page tunable (cli/main.cc): a running `serve` has it in its
# environment; LIDARSHOP_HUGE_PAGES=0 leaves it out, and a GLIBC_TUNABLES the user set is kept as it is.
environment_of_serve() {  # environment_of_serve OUT [VAR=VALUE ...]: the running serve's environment, one per line
  local out=$1
  shift
  start_serve "$@" --
  wait_for_url || {
    stop_serve KILL
    return 1
  }
  tr '\0' '\n' <"/proc/$serve_pid/environ" >"$out"
  stop_serve TERM
}
check "serve starts (huge pages)" environment_of_serve "$work/env_on"
check "the restart set glibc's huge-page tunable" grep -qx "GLIBC_TUNABLES=glibc.malloc.hugetlb=1" "$work/env_on"
check "serve starts (LIDARSHOP_HUGE_PAGES=0)" environment_of_serve "$work/env_off" LIDARSHOP_HUGE_PAGES=0
check "LIDARSHOP_HUGE_PAGES=0: no tunable" sh -c "! grep -q '^GLIBC_TUNABLES=' '$work/env_off'"
check "serve starts (the user's tunable)" environment_of_serve "$work/env_user" GLIBC_TUNABLES=glibc.malloc.arena_max=2
check "the user's tunable is kept" grep -qx "GLIBC_TUNABLES=glibc.malloc.arena_max=2" "$work/env_user"

finish
