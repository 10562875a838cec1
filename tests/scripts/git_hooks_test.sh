#!/usr/bin/env bash
# Tests scripts/git-hooks/commit-msg and scripts/install-git-hooks. Usage: git_hooks_test.sh SOURCE_DIR
# The hook is run on message files as git hands them over (comments, blank lines, the scissors of
# `commit -v`), then through real commits in a scratch repository set up by install-git-hooks; the
# installer must also do nothing, successfully, in a tarball and beside hooks a user already has.
set -euo pipefail
source_dir="$(cd "$1" && pwd)"
hook="$source_dir/scripts/git-hooks/commit-msg"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export GIT_CONFIG_NOSYSTEM=1 GIT_CONFIG_GLOBAL=/dev/null
export GIT_AUTHOR_NAME=test GIT_AUTHOR_EMAIL=test@example.com
export GIT_COMMITTER_NAME=test GIT_COMMITTER_EMAIL=test@example.com
failures=0

# subject N [CHAR]: a subject of N characters (CHAR repeated, default "a").
subject() { local s="" i; for ((i = 0; i < $1; i++)); do s+="${2:-a}"; done; printf '%s' "$s"; }
s72="$(subject 72)"
s73="$(subject 73)"

# expect accept|refuse NAME MESSAGE: runs the hook on MESSAGE.
expect() {
    printf '%s' "$3" >"$work/message"
    if (cd "$work" && "$hook" "$work/message") >"$work/hook_out" 2>&1; then got=accept; else got=refuse; fi
    if [ "$got" != "$1" ]; then
        echo "FAIL: $2: expected $1, the hook said $got"; cat "$work/hook_out"; failures=$((failures + 1))
    else
        echo "ok: $2 ($got)"
    fi
}
expect accept "72-character subject" "$s72"$'\n'
expect refuse "73-character subject" "$s73"$'\n'
expect accept "72 characters with a body of long lines" "$s72"$'\n\n'"$s73$s73"$'\n'
expect refuse "empty message" ""
expect refuse "blank lines only" $'\n  \n\n'
expect refuse "comment lines only" $'# Please enter the commit message\n#\n'
expect accept "a long comment line before the subject is ignored" \
    "# $s73$s73"$'\n'"$s72"$'\n'
expect refuse "a comment line does not hide a long subject after it" "# short"$'\n'"$s73"$'\n'
expect accept "leading blank lines and trailing blanks are dropped as git does" \
    $'\n\n'"$s72   "$'\n'
expect accept "72 characters of UTF-8 (144 bytes)" "$(subject 72 ö)"$'\n'
expect refuse "73 characters of UTF-8" "$(subject 73 ö)"$'\n'
expect refuse "the diff of commit -v is not the subject" \
    $'# ------------------------ >8 ------------------------\n'"$s72"$'\n'
expect accept "fixup! subjects are squashed away" "fixup! $s72"$'\n'

# install-git-hooks in a scratch checkout, then real commits.
repo="$work/repo"
mkdir -p "$repo/scripts"
cp -R "$source_dir/scripts/git-hooks" "$source_dir/scripts/install-git-hooks" "$repo/scripts/"
git -C "$repo" init -q
"$repo/scripts/install-git-hooks"
installed="$(git -C "$repo" config --get core.hooksPath || true)"
if [ "$installed" != "scripts/git-hooks" ]; then
    echo "FAIL: install-git-hooks set core.hooksPath to '$installed'"; failures=$((failures + 1))
fi
"$repo/scripts/install-git-hooks" >/dev/null  # again: nothing changes, no failure
if git -C "$repo" commit -q --allow-empty -m "$s73" 2>/dev/null; then
    echo "FAIL: git commit accepted a 73-character subject"; failures=$((failures + 1))
else
    echo "ok: git commit refused a 73-character subject"
fi
if git -C "$repo" commit -q --allow-empty -m "$s72" -m "$s73$s73"; then
    echo "ok: git commit accepted a 72-character subject"
else
    echo "FAIL: git commit refused a 72-character subject"; failures=$((failures + 1))
fi

# A tarball: no git checkout, nothing to install, success.
tarball="$work/tarball"
mkdir -p "$tarball/scripts"
cp -R "$source_dir/scripts/git-hooks" "$source_dir/scripts/install-git-hooks" "$tarball/scripts/"
if ! "$tarball/scripts/install-git-hooks" >"$work/out" 2>&1 || ! grep -q "not a git checkout" "$work/out"; then
    echo "FAIL: install-git-hooks outside a git checkout:"; cat "$work/out"; failures=$((failures + 1))
fi
# A checkout whose user has hooks of their own: left alone.
own="$work/own"
mkdir -p "$own/scripts"
cp -R "$source_dir/scripts/git-hooks" "$source_dir/scripts/install-git-hooks" "$own/scripts/"
git -C "$own" init -q
printf '#!/bin/sh\nexit 0\n' >"$own/.git/hooks/pre-commit"
chmod +x "$own/.git/hooks/pre-commit"
"$own/scripts/install-git-hooks" >/dev/null
if [ -n "$(git -C "$own" config --get core.hooksPath || true)" ]; then
    echo "FAIL: install-git-hooks replaced the user's own hooks"; failures=$((failures + 1))
fi

if [ "$failures" -ne 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "git hooks: all checks passed"
