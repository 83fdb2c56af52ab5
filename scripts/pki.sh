#!/usr/bin/env bash
# A run's public-key infrastructure for DDS Security (openssl): a certificate authority, a
# certificate and key per participant, the governance document and a permissions document per
# role, signed by the authority. Give a process its participant's directory (or the whole
# directory and its name): `--dds-security DIR/actor-0`, or `--dds-security DIR --dds-identity
# actor-0`; `auvrl train --transport dds --dds-security DIR` names each process itself.
#
#   scripts/pki.sh --out DIR [--actors N] [--controllers N] [--days D] [--domain D]
#                  [--participant ROLE:NAME]...
#
# Participants: learner, logger, launcher (observer), operator, actor-I and sim-I for I < N
# (default 2), controller-I for I < --controllers (default 1), and each --participant (roles:
# `auvrl dds-policy roles`). The roles' grants (which topics each may publish and read) come
# from `auvrl dds-policy` (common/dds_security.cpp), so the documents match the build.
# --domain: the system's DDS domain (default 0; `--dds-domain` of the processes): everything
# on it is encrypted; other domains are lockstep pairs' loopback-only buses.
#
# DIR/ca/ca.key           the authority's private key (mode 0600; keep it off the hosts)
# DIR/ca/ca.pem           its certificate (identity CA and permissions CA)
# DIR/governance.p7s      the domain's rules, signed (DIR/governance.xml unsigned)
# DIR/permissions/R.p7s   role R's grants, signed, one per participant of the role
# DIR/NAME/               what participant NAME needs: identity_ca.pem, cert.pem, key.pem
#                         (0600), permissions_ca.pem, governance.p7s, permissions.p7s
# An existing DIR is refused: a new authority per run, never a half-overwritten one.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${AUVRL_BIN_DIR:-$root/build/bin}
usage() { sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }

out="" actors=2 controllers=1 days=30 domain=0
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --actors) actors=$2; shift 2 ;;
    --controllers) controllers=$2; shift 2 ;;
    --days) days=$2; shift 2 ;;
    --domain) domain=$2; shift 2 ;;
    --participant) extra+=("$2"); shift 2 ;;
    -h|--help) usage ;;
    *) echo "pki.sh: unknown argument '$1'" >&2; usage ;;
  esac
done
[ -n "$out" ] || { echo "pki.sh: --out DIR is required" >&2; usage; }
for n in "$actors" "$controllers" "$days" "$domain"; do
  [[ "$n" =~ ^[0-9]+$ ]] || { echo "pki.sh: expected a number, got '$n'" >&2; exit 2; }
done
[ -x "$bin/auvrl" ] || { echo "pki.sh: $bin/auvrl is missing (build first)" >&2; exit 1; }
command -v openssl >/dev/null || { echo "pki.sh: openssl is missing (scripts/install-deps.sh)" >&2; exit 1; }
[ ! -e "$out" ] || { echo "pki.sh: $out exists; refusing to overwrite a PKI" >&2; exit 1; }

# ROLE:NAME of every participant.
participants=(learner:learner logger:logger observer:launcher operator:operator)
for ((i = 0; i < actors; i++)); do participants+=("actor:actor-$i" "simulator:sim-$i"); done
for ((i = 0; i < controllers; i++)); do participants+=("controller:controller-$i"); done
participants+=("${extra[@]+"${extra[@]}"}")
roles=$("$bin/auvrl" dds-policy roles | cut -f1)
for p in "${participants[@]}"; do
  role=${p%%:*} name=${p#*:}
  grep -qx "$role" <<<"$roles" || {
    echo "pki.sh: unknown role '$role' in '$p' (roles: ${roles//$'\n'/ })" >&2
    exit 2
  }
  [[ "$name" =~ ^[A-Za-z0-9_.-]+$ ]] || { echo "pki.sh: bad participant name '$name'" >&2; exit 2; }
done

tmp="$out.partial.$$"
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/ca" "$tmp/permissions"
umask 077
ec_key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null; }
sign() { openssl smime -sign -in "$1" -text -out "$2" -signer "$tmp/ca/ca.pem" -inkey "$tmp/ca/ca.key"; }

run_id="auvrl $(date -u +%Y%m%dT%H%M%SZ)-$$"
ec_key "$tmp/ca/ca.key"
openssl req -x509 -new -key "$tmp/ca/ca.key" -days "$days" -subj "/O=$run_id/CN=auvrl CA" \
  -out "$tmp/ca/ca.pem" 2>/dev/null
not_before=$(date -u -d '-1 hour' +%Y-%m-%dT%H:%M:%S)
not_after=$(date -u -d "+$days days" +%Y-%m-%dT%H:%M:%S)

"$bin/auvrl" dds-policy governance --system-domain "$domain" >"$tmp/governance.xml"
sign "$tmp/governance.xml" "$tmp/governance.p7s"
for role in $roles; do
  subjects=()
  for p in "${participants[@]}"; do
    [ "${p%%:*}" = "$role" ] && subjects+=(--subject "CN=${p#*:},O=$run_id")
  done
  [ ${#subjects[@]} -gt 0 ] || continue
  "$bin/auvrl" dds-policy permissions --role "$role" "${subjects[@]}" --not-before "$not_before" \
    --not-after "$not_after" >"$tmp/permissions/$role.xml"
  sign "$tmp/permissions/$role.xml" "$tmp/permissions/$role.p7s"
done

for p in "${participants[@]}"; do
  role=${p%%:*} name=${p#*:}
  d="$tmp/$name"
  mkdir -p "$d"
  ec_key "$d/key.pem"
  openssl req -new -key "$d/key.pem" -subj "/O=$run_id/CN=$name" 2>/dev/null |
    openssl x509 -req -CA "$tmp/ca/ca.pem" -CAkey "$tmp/ca/ca.key" -CAcreateserial \
      -CAserial "$tmp/ca/ca.srl" -days "$days" -out "$d/cert.pem" 2>/dev/null
  cp "$tmp/ca/ca.pem" "$d/identity_ca.pem"
  cp "$tmp/ca/ca.pem" "$d/permissions_ca.pem"
  cp "$tmp/governance.p7s" "$d/governance.p7s"
  cp "$tmp/permissions/$role.p7s" "$d/permissions.p7s"
  echo "$role" >"$d/role"
done
chmod -R go+rX "$tmp"
chmod 600 "$tmp/ca/ca.key" "$tmp"/*/key.pem
chmod 700 "$tmp/ca"
mv "$tmp" "$out"
trap - EXIT
echo "pki.sh: $out: authority '$run_id', ${#participants[@]} participants:" \
  "$(for p in "${participants[@]}"; do printf '%s ' "${p#*:}"; done)"
