#!/usr/bin/env bash
# Fails when a relative link or image in the project's Markdown names a file
# that does not exist: README.md and the other top-level pages, docs/ and
# scenes/README.md. Links to web pages (a scheme such as https:) and to
# anchors within a page are not files; a link's own anchor (#section) is
# dropped before the check.
#   check_links.sh SOURCE_DIR
set -euo pipefail
cd "$1"
missing=0 checked=0
for page in *.md docs/*.md scenes/README.md; do
    folder=$(dirname "$page")
    # Inline links and images, [text](target) and ![alt](target "title"), and HTML images.
    while IFS= read -r target; do
        case $target in
            [a-zA-Z]*:* | '#'*) continue ;;
        esac
        target=${target%%#*}
        checked=$((checked + 1))
        if [[ ! -e $folder/$target ]]; then
            echo "$page: links to '$target', which does not exist" >&2
            missing=$((missing + 1))
        fi
    done < <(grep -oE '\]\([^) ]+' "$page" | cut -c3-; grep -oE '<img [^>]*src="[^"]+' "$page" | sed 's/.*src="//')
done
[[ $missing -eq 0 ]] || exit 1
echo "$checked relative links and images exist"
