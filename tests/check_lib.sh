# Check helpers shared by the end-to-end shell tests (cli_test.sh, points_cli_test.sh). The sourcing script sets
# `work` (a scratch folder) and the counters `passed` and `failed`.

check() {  # check NAME COMMAND...: the command must succeed
  local name=$1
  shift
  if "$@" >"$work/last.out" 2>"$work/last.err"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED: $name: $*"
    sed 's/^/  | /' "$work/last.out" "$work/last.err" | head -20
  fi
}

fails_clearly() {  # fails_clearly NAME PATTERN COMMAND...: non-zero exit, one line on stderr matching PATTERN
  local name=$1 pattern=$2
  shift 2
  if "$@" >"$work/last.out" 2>"$work/last.err"; then
    failed=$((failed + 1))
    echo "FAILED: $name: succeeded but should have failed: $*"
    return
  fi
  if [ "$(wc -l <"$work/last.err")" -eq 1 ] && grep -qE -e "$pattern" "$work/last.err"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED: $name: expected one line matching '$pattern' on stderr, got:"
    sed 's/^/  | /' "$work/last.err" | head -10
  fi
}

json_check() {  # json_check NAME FILE PYTHON_EXPRESSION (on `d`, the parsed JSON)
  check "$1" python3 -c "import json,sys,math; d=json.load(open(sys.argv[1])); assert ($3), 'expression false'" "$2"
}
