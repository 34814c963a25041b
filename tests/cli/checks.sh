# A pass/fail counter for the CLI tests that need no harness.sh: `check NAME STATUS [DETAIL]`
# prints "ok - NAME" when STATUS is 0, else "not ok - NAME: DETAIL"; `finish` prints the
# closing "N passed, N failed" line and returns non-zero after a failure.
passed=0
failed=0
check() {
  if [ "$2" -eq 0 ]; then
    echo "ok - $1"
    passed=$((passed + 1))
  else
    echo "not ok - $1${3:+: $3}"
    failed=$((failed + 1))
  fi
}
finish() {
  echo "$passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
