#!/usr/bin/env bash
# Checks that the manual (README.md) and doc/ agree with the package: every launch file argument
# and every tool is named in README.md, each tool answers --help, README.md stays a manual (at
# most 400 lines), no page carries work history ("session"), every relative link resolves, every
# generated block of doc/regenerate.sh is closed, and the section names the code's comments cite
# (README, then the name in quotes) exist as headings in README.md or doc/; the scripts parse. Cheap: no build of
# its own, a few seconds.
#
# Usage: scripts/check_docs.sh [BUILD_DIR]
#   BUILD_DIR  a build of this package (e.g. build/): the tools built there must answer --help
#              (looked for in BUILD_DIR/devel/lib/cvo_odometry, else anywhere below BUILD_DIR; one
#              not built, e.g. cvo_make_bag in a build without ROS, is noted); without BUILD_DIR
#              that check is skipped
# Prints one line per problem and a summary; exits 1 when anything failed.
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
build=${1:-}
failures=0
fail() { echo "check_docs: $*"; failures=$((failures + 1)); }

readme=README.md
[ -f "$readme" ] || { echo "check_docs: no $readme" >&2; exit 1; }

# 1. README.md is a manual: at most 400 lines.
lines=$(wc -l <"$readme")
[ "$lines" -le 400 ] || fail "$readme has $lines lines (at most 400)"

# 2. No work history in the documents (git log carries it).
while IFS= read -r hit; do
  fail "history in the documents: $hit"
done < <(grep -rniw -e 'session' -e 'sessions' "$readme" doc/*.md 2>/dev/null)

# 3. Every launch file argument is named in README.md (as `name`).
for launch in launch/*.launch; do
  for arg in $(sed -n 's/.*<arg name="\([^"]*\)".*/\1/p' "$launch" | sort -u); do
    grep -q "\`$arg\`" "$readme" || fail "$launch: argument '$arg' is not in $readme"
  done
done

# 4. Every tool is named in README.md: the programs of src/tools, src/ros and bench, and the
#    bench scripts.
tools=$(sed -n 's/^ *add_executable(\([a-z_0-9]*\) .*/\1/p' src/tools/CMakeLists.txt \
          src/ros/CMakeLists.txt bench/CMakeLists.txt | sort -u)
for tool in $tools; do
  case "$tool" in cvo_odometry_nodelet|cvo_peers) continue ;; esac  # the nodelet; bench's peers
  grep -q "$tool" "$readme" || fail "tool $tool is not in $readme"
done
for script in bench/*.sh; do
  name=$(basename "$script" .sh)
  case "$name" in peer_build) continue ;; esac  # sourced by the other bench scripts
  grep -q "$name" "$readme" || fail "bench script $script is not in $readme"
done

# 5. Relative links of README.md and doc/*.md resolve (anchors are not checked).
for page in "$readme" doc/*.md; do
  [ -f "$page" ] || continue
  dir=$(dirname "$page")
  for target in $(grep -oE '\]\([^)#: ]+' "$page" | sed 's/^](//' | sort -u); do
    [ -e "$dir/$target" ] || fail "$page: link to $target, which does not exist"
  done
done

# 5b. Anchors (#section) of links within README.md and doc/ name a heading of their page (GitHub's
#     rule: lower case, punctuation dropped, spaces to dashes).
while IFS= read -r problem; do
  fail "$problem"
done < <(python3 - "$readme" doc/*.md <<'PY'
import os, re, sys
def slugs(page):
    out = set()
    for line in open(page):
        m = re.match(r"#+ (.*)", line)
        if m:
            text = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower().replace("`", ""))
            out.add(text.replace(" ", "-"))
    return out
for page in sys.argv[1:]:
    if not os.path.isfile(page):
        continue
    for target, anchor in re.findall(r"\]\(([^)#: ]*)#([^) ]+)\)", open(page).read()):
        path = os.path.normpath(os.path.join(os.path.dirname(page), target)) if target else page
        if os.path.isfile(path) and anchor not in slugs(path):
            print(f"{page}: link to {target}#{anchor}: no such heading")
PY
)

# 6. Generated blocks are closed, one end per start (doc/regenerate.sh).
for page in "$readme" doc/*.md; do
  [ -f "$page" ] || continue
  starts=$(grep -cE '^<!-- generated( text)?: .* -->$' "$page")
  ends=$(grep -c '^<!-- end generated -->$' "$page")
  [ "$starts" = "$ends" ] || fail "$page: $starts generated blocks opened, $ends closed"
done

# 7. Section names that comments in the code cite as README "Name" exist as a heading.
headings=$(grep -h '^#' "$readme" doc/*.md 2>/dev/null | sed 's/^#* *//')
while IFS= read -r cited; do
  name=$(sed 's/^README[: ]*"\(.*\)"$/\1/' <<<"$cited")
  grep -qiF "$name" <<<"$headings" ||
    fail "cited as README \"$name\" ($(grep -rlF "\"$name\"" src include config msg cfg test \
      scripts bench launch 2>/dev/null | grep -v '/fuzz/corpus/' | paste -sd' ')), no such heading"
done < <(grep -rhoE --exclude=check_docs.sh 'README[: ]*"[^"]+"' src include config msg cfg \
           test scripts bench launch 2>/dev/null | sort -u)

# 8. Each tool answers --help (exit 0, some output).
if [ -n "$build" ]; then
  [ -d "$build" ] || { echo "check_docs: no build folder $build" >&2; exit 2; }
  for tool in $tools; do
    case "$tool" in cvo_odometry_nodelet|cvo_peers|cvo_settings_table) continue ;; esac
    exe="$build/devel/lib/cvo_odometry/$tool"
    [ -x "$exe" ] || exe=$(find "$build" -name "$tool" -type f -perm -u+x 2>/dev/null | head -1)
    if [ -z "$exe" ] || [ ! -x "$exe" ]; then
      echo "check_docs: note: $tool is not built in $build (--help not checked)"
      continue
    fi
    out=$("$exe" --help 2>&1) && [ -n "$out" ] || fail "$tool --help failed: $(head -1 <<<"$out")"
  done
fi

# 9. The scripts the manual names parse.
for script in bench/*.sh scripts/*.sh doc/*.sh; do
  bash -n "$script" 2>/dev/null || fail "$script does not parse (bash -n)"
done

if [ "$failures" -eq 0 ]; then
  echo "check_docs: README.md ($lines lines) and doc/ agree with the package"
else
  echo "check_docs: $failures problems"
  exit 1
fi
