#!/usr/bin/env bash
# lcm-spy with the nudge types on its CLASSPATH. Debian's /usr/bin/lcm-spy passes -Xincgc,
# which Java 17 rejects, so start the Spy class directly.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
nudge_install_packages
nudge_build
jar="$NUDGE_BUILD_DIR/share/nudge_lcmtypes.jar"
[ -f "$jar" ] || { nudge_log "missing $jar (is javac installed?)"; exit 1; }
export CLASSPATH="$jar:/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar${CLASSPATH:+:$CLASSPATH}"
exec java -server -Djava.net.preferIPv4Stack=true -ea lcm.spy.Spy "$@"
