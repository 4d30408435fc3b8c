#!/bin/sh
# Hardens the decoders lcm-gen (LCM 1.3.1) writes, in place, so that a malformed message can
# neither allocate what it merely declares nor read past its bytes (docs/reliability.md):
#  - a string whose declared length is below 1 (it counts the terminating NUL) is refused; the
#    generated check only refuses lengths beyond the bytes left, and assign(p, len - 1) on
#    len = INT_MIN reads 2 GB past the buffer;
#  - a variable-length array whose declared count is negative or larger than the bytes left is
#    refused before resize() allocates it (every element takes at least one byte).
# Usage: harden_lcm_headers.sh HEADER...
set -eu
for header in "$@"; do
  sed -i \
    -e 's/if(\(__[A-Za-z0-9_]*len_*\) > maxlen - pos) return -1;/if(\1 < 1 || \1 > maxlen - pos) return -1;/' \
    -e 's/^\( *\)this->\([A-Za-z0-9_]*\)\.resize(this->\([A-Za-z0-9_]*\));/\1if(this->\3 < 0 || this->\3 > maxlen - pos) return -1;\n\1this->\2.resize(this->\3);/' \
    "$header"
done
