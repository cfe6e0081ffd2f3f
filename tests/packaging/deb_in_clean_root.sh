#!/usr/bin/env bash
# The packages of a build tree (`cpack` in BUILD_DIR) installed with apt into a bare Debian
# bookworm root (debootstrap, minbase) that holds no source or build tree: the demo graph
# measures there from /usr/share/tilth, and `systemd-analyze verify` passes the unit.
# The bare root is made once and kept in ~/.cache/tilth; each run starts from it afresh.
# Usage: bash tests/packaging/deb_in_clean_root.sh BUILD_DIR
set -euo pipefail
build=$(cd "${1:?usage: deb_in_clean_root.sh BUILD_DIR}" && pwd)
cache=${XDG_CACHE_HOME:-$HOME/.cache}/tilth/bookworm-minbase.tar
# This host's Debian mirror (deb822 sources or sources.list), else Debian's own.
mirror=$(sed -n 's/^URIs: *//p' /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -1 || true)
[ -n "$mirror" ] || mirror=$(awk '/^deb /{print $2; exit}' /etc/apt/sources.list 2>/dev/null || true)
mirror=${mirror:-http://deb.debian.org/debian}

root=$(mktemp -d /tmp/tilth-deb-root.XXXXXX)
chmod 755 "$root"  # apt downloads as _apt
unmount() { for m in proc dev; do umount -l "$root/$m" 2>/dev/null || true; done; }
trap 'unmount; rm -rf "$root"' EXIT

if [ ! -f "$cache" ]; then
  echo "deb_in_clean_root: making a bare bookworm root (once) from $mirror"
  mkdir -p "$(dirname "$cache")"
  debootstrap --variant=minbase bookworm "$root" "$mirror" > "$root.debootstrap.log" 2>&1 ||
    { tail -20 "$root.debootstrap.log"; exit 1; }
  rm -f "$root.debootstrap.log"
  tar -C "$root" -cf "$cache.partial" . && mv "$cache.partial" "$cache"
  rm -rf "$root" && mkdir "$root"
fi
tar -C "$root" -xf "$cache"

(cd "$build" && cpack -G DEB > cpack.log) || { tail -20 "$build/cpack.log"; exit 1; }
cp "$build"/tilth_*.deb "$root/tmp/"
cp /etc/resolv.conf "$root/etc/resolv.conf"
# The extra CA certificates this host trusts (package mirrors behind a TLS proxy).
if ls /usr/local/share/ca-certificates/*.crt > /dev/null 2>&1; then
  mkdir -p "$root/usr/local/share/ca-certificates"
  cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/"
fi
mount -t proc proc "$root/proc"
mount --bind /dev "$root/dev"

inside() { chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root "$@"; }
inside apt-get update -qq > /dev/null
echo "deb_in_clean_root: apt-get install ./tilth_*.deb systemd"
inside /bin/sh -c 'DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
  /tmp/tilth_*.deb systemd' > "$root/install.log" 2>&1 || { tail -30 "$root/install.log"; exit 1; }

out=$(inside /bin/sh -c 'cd / && tilth run /usr/share/tilth/graphs/demo.json --frames 20 2>&1')
echo "$out" | tail -3
echo "$out" | grep -q '^20 frames completed' ||
  { echo "deb_in_clean_root: the demo graph did not complete 20 frames"; exit 1; }
# sinks.console's lines: within 1 mm of the simulator's truth, 518 mm (case C; the chain
# measures it to 0.04 mm).
measured=$(echo "$out" | grep -cE '^frame [0-9]+: 51[78]\.[0-9]+ mm' || true)
[ "$measured" -ge 1 ] || { echo "deb_in_clean_root: no distance within 1 mm of 518 mm printed"; exit 1; }

mkdir -p "$root/etc/tilth" && cp "$root/usr/share/tilth/graphs/seeder.json" "$root/etc/tilth/"
inside tilth validate /etc/tilth/seeder.json
inside systemd-analyze verify tilth@seeder.service
echo "deb_in_clean_root: passed"
