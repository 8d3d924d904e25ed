#!/bin/bash
# Headless simulated LinuxCNC mill (mill.ini / mill.hal beside this script) for the LinuxCNC
# backend's tests: start, stop, and fault helpers. See --help.
set -u -o pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
PROG="$(basename "$0")"

PORT="${LCNC_SIM_PORT:-5007}"
CONNECTPW="${LCNC_SIM_CONNECTPW:-SimMillHello}"
ENABLEPW="${LCNC_SIM_ENABLEPW:-SimMillEnable}"
NAME="${LCNC_SIM_NAME:-SIMMILL}"
SESSIONS="${LCNC_SIM_SESSIONS:--1}"
SIM_USER="${LCNC_SIM_USER:-nobody}"
START_TIMEOUT="${LCNC_SIM_START_TIMEOUT:-30}"
LOOPBACK_ONLY="${LCNC_SIM_LOOPBACK_ONLY:-0}"
STOP_TIMEOUT="${LCNC_SIM_STOP_TIMEOUT:-10}"

# LinuxCNC's own fixed host-wide state (the linuxcnc script and rtapi hard-code these).
LOCKFILE=/tmp/linuxcnc.lock
# SysV shared memory keys: NML channels 1001..1005 (mill.nml), motion (100), HAL, RTAPI, UUID,
# and sampler's HAL stream.
SHM_KEYS="0x000003e9 0x000003ea 0x000003eb 0x000003ec 0x000003ed 0x00000064 0x48414c32 0x90280a48 0x48484c34 0x48534130"
LCNC_PROCS="linuxcnc linuxcncsvr rtapi_app milltask io iocontrol linuxcncrsh halsampler halcmd inihal"

usage() {
    cat <<EOF
Usage: $PROG [options] COMMAND DIR [ARGS]

Runs the simulated 3-axis mill (X 0..50, Y 0..25, Z 0..25 mm; 5 mm/s, 50 mm/s^2 per axis) under
the real LinuxCNC (uspace, 1 ms servo thread), headless, with linuxcncrsh as its only interface.
DIR is the instance's folder: the config is copied there and everything LinuxCNC writes goes there
(HOME=DIR; rtapi_app's socket in /tmp/lcnc-sim-UID, short enough for any DIR). Only one LinuxCNC can run on a host.

Commands:
  start DIR      Copy the config to DIR (created if missing; an old instance's files there are
                 replaced), start LinuxCNC in the background as the unprivileged user, start
                 halsampler writing DIR/samples.txt, wait (at most LCNC_SIM_START_TIMEOUT s) until
                 linuxcncrsh answers a hello on the port. Prints key=value lines (port, pids,
                 files, seconds). Exit 1 with LinuxCNC's log if it cannot start, 2 if another
                 LinuxCNC runs or the port is taken.
  stop DIR       Stop it whatever its state: linuxcncrsh is sent TERM so LinuxCNC shuts down in
                 order; after LCNC_SIM_STOP_TIMEOUT s (or at once if that is 0) every process of the
                 instance is killed; then LinuxCNC's lock file and shared memory are removed.
                 Idempotent; also cleans up after "kill". Prints seconds=...
  status DIR     Exit 0 and print the pids if the instance runs, 1 if not.
  estop DIR [press|release]
                 Press (default) or release the external e-stop button (HAL signal estop-ext-ok
                 0 / 1). While pressed, LinuxCNC goes to e-stop and "set estop off" cannot leave it.
                 Prints estop-ext-ok=0|1 set_between=T0,T1: halcmd set the signal between those
                 CLOCK_REALTIME seconds (the instance look-up before it can take a second).
  ferror DIR [JOINT [MAXV]]
                 Make the simulated motor of JOINT (0=X 1=Y 2=Z, default 0) slower: limit3.JOINT.maxv
                 = MAXV mm/s (default 0.5) so the next move of that joint ends in a following
                 error. "ferror DIR reset" puts every motor back to 6 mm/s.
  kill DIR       Kill every process of the instance with SIGKILL at once, as a crash would (the
                 socket closes; lock file and shared memory stay until "stop DIR"). halsampler is
                 let drain the samples that were taken, then stopped. Prints killed=PIDS
                 kill_between=T0,T1: the SIGKILL was sent between those CLOCK_REALTIME seconds
                 (the instance look-up before it can take a second).
  hal DIR ARGS   Run "halcmd ARGS" against the instance (as its user), e.g. hal DIR getp limit3.0.out

Options (or the environment variables):
  --port N            LCNC_SIM_PORT        linuxcncrsh's TCP port (default 5007)
  --connectpw PW      LCNC_SIM_CONNECTPW   hello password (default SimMillHello; at most 15 chars)
  --enablepw PW       LCNC_SIM_ENABLEPW    "set enable" password (default SimMillEnable; <= 15)
  --name NAME         LCNC_SIM_NAME        server name in HELLO ACK (default SIMMILL; <= 23)
  --sessions N        LCNC_SIM_SESSIONS    linuxcncrsh --sessions (default -1, no limit; see README:
                                           the count never goes down, so N limits connections ever)
  --user USER         LCNC_SIM_USER        user LinuxCNC runs as when started by root (default nobody)
  --timeout S         LCNC_SIM_START_TIMEOUT  start's bounded wait (default 30)
  --loopback-only     LCNC_SIM_LOOPBACK_ONLY=1  linuxcncrsh always listens on every address
                      (0.0.0.0, no option to change it): as root, start inserts
                        iptables -I INPUT -p tcp --dport PORT ! -i lo -j REJECT --reject-with tcp-reset
                      and stop deletes it (off by default: it changes the host's firewall)
  -h, --help

Files in DIR: mill.ini mill.hal mill.nml mill.tbl mill.var (config), linuxcnc.log (LinuxCNC's
stdout and stderr), halsampler.log, samples.txt (ground truth, one line per 1 ms servo period:
sample number, X Y Z motor position, X Y Z position command, spindle speed command in rpm,
machine on 0/1, spindle on 0/1; an "overrun" line marks lost samples), sim.env (what start printed).
EOF
}

die() { echo "$PROG: $*" >&2; exit 1; }

# ---- option parsing
ARGS=()
while [ $# -gt 0 ]; do
    case "$1" in
        -h|--help) usage; exit 0 ;;
        --port) PORT="$2"; shift 2 ;;
        --connectpw) CONNECTPW="$2"; shift 2 ;;
        --enablepw) ENABLEPW="$2"; shift 2 ;;
        --name) NAME="$2"; shift 2 ;;
        --sessions) SESSIONS="$2"; shift 2 ;;
        --user) SIM_USER="$2"; shift 2 ;;
        --timeout) START_TIMEOUT="$2"; shift 2 ;;
        --loopback-only) LOOPBACK_ONLY=1; shift ;;
        --) shift; ARGS+=("$@"); break ;;
        *) ARGS+=("$1"); shift ;;
    esac
done
set -- "${ARGS[@]+"${ARGS[@]}"}"
[ $# -ge 1 ] || { usage >&2; exit 64; }
CMD="$1"; shift
case "$CMD" in
    help) usage; exit 0 ;;
esac
[ $# -ge 1 ] || die "$CMD needs DIR (try --help)"
DIR_ARG="$1"; shift
if [ "$CMD" = start ]; then
    mkdir -p "$DIR_ARG" 2>/dev/null || true
    [ -d "$DIR_ARG" ] || die "cannot use $DIR_ARG as the instance folder"
fi
if [ -d "$DIR_ARG" ]; then DIR="$(cd "$DIR_ARG" && pwd -P)"; else DIR="$(realpath -m "$DIR_ARG")"; fi

# ---- who runs LinuxCNC
if [ "$(id -u)" = 0 ]; then
    RUN_UID="$(id -u "$SIM_USER" 2>/dev/null)" || die "no user $SIM_USER (set LCNC_SIM_USER)"
    RUN_GID="$(id -g "$SIM_USER")"
    [ "$RUN_UID" != 0 ] || die "LCNC_SIM_USER must not be root"
    # no_new_privs: rtapi_app is setuid root; this keeps it (and everything) unprivileged.
    AS_USER=(setpriv --reuid="$RUN_UID" --regid="$RUN_GID" --clear-groups --no-new-privs)
else
    RUN_UID="$(id -u)"; RUN_GID="$(id -g)"
    AS_USER=(setpriv --no-new-privs)
fi

# rtapi_app's socket is a unix socket: its path must fit in 108 bytes, which DIR/.rtapi_fifo does
# not in a deep build tree (a CI checkout's test folder). It lives in a short folder of its own,
# one per user (only one LinuxCNC runs on a host anyway).
FIFO_DIR="/tmp/lcnc-sim-$RUN_UID"
FIFO="$FIFO_DIR/rtapi_fifo"
fifo_dir_ready() {
    if [ -L "$FIFO_DIR" ] || { [ -e "$FIFO_DIR" ] && [ ! -d "$FIFO_DIR" ]; }; then
        die "$FIFO_DIR is not a plain folder: remove it (rtapi_app's socket goes there)"
    fi
    mkdir -p -m 700 "$FIFO_DIR" 2>/dev/null || die "cannot create $FIFO_DIR for rtapi_app's socket"
    [ "$(id -u)" != 0 ] || chown "$RUN_UID:$RUN_GID" "$FIFO_DIR" || die "cannot chown $FIFO_DIR to $SIM_USER"
    [ "$(stat -c %u "$FIFO_DIR")" = "$RUN_UID" ] || die "$FIFO_DIR belongs to another user: remove it"
    chmod 700 "$FIFO_DIR"
}

# Every process of the instance carries LCNC_SIM_DIR=DIR in its environment: that is how stop and
# kill find them (rtapi_app and linuxcncsvr start their own sessions, so a process group is not
# enough), and nothing else on the host is touched.
as_user() { "${AS_USER[@]}" env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME="$DIR" RTAPI_FIFO_PATH="$FIFO" LANG=C.UTF-8 \
    LC_ALL=C.UTF-8 USER="$SIM_USER" LOGNAME="$SIM_USER" TMPDIR="$DIR" LCNC_SIM_DIR="$DIR" "$@"; }

instance_pids() {   # live (non-zombie) processes whose environment holds LCNC_SIM_DIR=$DIR
    local pids
    pids="$(grep -lzxF "LCNC_SIM_DIR=$DIR" /proc/[0-9]*/environ 2>/dev/null | cut -d/ -f3 | grep -vx "$$")"
    [ -n "$pids" ] || return 0
    ps -o pid=,stat= -p "$(echo $pids | tr ' ' ,)" 2>/dev/null | awk '$2 !~ /^Z/ {print $1}'
}

lcnc_pids_any() {   # any live LinuxCNC process on the host (read-only look-up by exact name;
                    # zombies waiting for init to reap them do not count)
    ps -C linuxcncsvr,rtapi_app,milltask,linuxcncrsh -o pid=,stat= 2>/dev/null | awk '$2 !~ /^Z/ {print $1}'
}

port_busy() { (exec 3<>"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null; }

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN{printf "%.2f", b-a}'; }

cleanup_host_state() {
    # Only when no LinuxCNC process is left anywhere: the lock file and shared memory are
    # host-wide and belong to whichever LinuxCNC runs.
    if [ -n "$(lcnc_pids_any)" ]; then return 0; fi
    rm -f "$LOCKFILE" 2>/dev/null || true
    local k
    if command -v ipcrm >/dev/null; then
        for k in $SHM_KEYS; do ipcrm -M "$k" 2>/dev/null || true; done
    fi
    # the linuxcnc script's temp logs (it removes them itself unless killed)
    find /tmp -maxdepth 1 \( -name 'linuxcnc.debug.*' -o -name 'linuxcnc.print.*' \) \
        -uid "$RUN_UID" -delete 2>/dev/null || true
    rm -f "$DIR/.rtapi_fifo" "$FIFO" 2>/dev/null || true
}

hello_ok() {   # one hello on the port; true if HELLO ACK comes back within 2 s
    local line=""
    { exec 3<>"/dev/tcp/127.0.0.1/$PORT"; } 2>/dev/null || return 1
    printf 'hello %s lcnc-sim-probe 1.1\r\n' "$CONNECTPW" >&3
    IFS= read -r -t 2 line <&3 || true
    exec 3<&- 3>&-
    [[ "$line" == "HELLO ACK"* ]]
}

FW_RULE=(INPUT -p tcp --dport "$PORT" ! -i lo -j REJECT --reject-with tcp-reset)
firewall_on() {
    [ "$(id -u)" = 0 ] || die "--loopback-only needs root (iptables)"
    command -v iptables >/dev/null || die "--loopback-only needs iptables"
    iptables -C "${FW_RULE[@]}" 2>/dev/null || iptables -I "${FW_RULE[@]}" || die "iptables could not add the rule"
}
firewall_off() {   # the rule start added, if sim.env says so
    local p
    [ -f "$DIR/sim.env" ] && grep -qx 'loopback_only=1' "$DIR/sim.env" || return 0
    p="$(sed -n 's/^port=//p' "$DIR/sim.env")"
    [ -n "$p" ] && command -v iptables >/dev/null || return 0
    while iptables -D INPUT -p tcp --dport "$p" ! -i lo -j REJECT --reject-with tcp-reset 2>/dev/null; do :; done
}

cmd_start() {
    local t0; t0="$(now)"
    case "$CONNECTPW$ENABLEPW$NAME" in *[!A-Za-z0-9_.+-]*) die "passwords and name: letters, digits, _ . + - only" ;; esac
    [ ${#CONNECTPW} -le 15 ] && [ ${#ENABLEPW} -le 15 ] || die "linuxcncrsh keeps at most 15 characters of a password"
    [ ${#NAME} -le 23 ] || die "linuxcncrsh keeps at most 23 characters of the name"
    [[ "$PORT" =~ ^[0-9]+$ ]] || die "bad port $PORT"
    [[ "$SESSIONS" =~ ^-?[0-9]+$ ]] || die "bad sessions $SESSIONS"

    local others; others="$(lcnc_pids_any | tr '\n' ' ')"
    if [ -n "$others" ]; then
        echo "$PROG: another LinuxCNC is running (pids $others); only one can run on a host. Stop it first (stop DIR)." >&2
        exit 2
    fi
    if port_busy; then
        echo "$PROG: port $PORT is already taken; set LCNC_SIM_PORT (linuxcncrsh would silently listen elsewhere)" >&2
        exit 2
    fi
    # stale state from a LinuxCNC that died
    cleanup_host_state
    firewall_off

    # fresh config in DIR
    rm -f "$DIR/samples.txt" "$DIR/linuxcnc.log" "$DIR/halsampler.log" "$DIR/sim.env" \
        "$DIR/linuxcnc_debug.txt" "$DIR/linuxcnc_print.txt" "$DIR/.tool.mmap" "$DIR/mill.var"
    cp "$HERE/mill.ini" "$HERE/mill.hal" "$HERE/mill.nml" "$HERE/mill.tbl" "$DIR/" || die "cannot copy the config to $DIR"
    if [ "$LOOPBACK_ONLY" = 1 ]; then
        firewall_on
        printf 'port=%s\nloopback_only=1\n' "$PORT" > "$DIR/sim.env"   # so stop removes the rule
    fi
    sed -i -e "s|@PORT@|$PORT|" -e "s|@NAME@|$NAME|" -e "s|@CONNECTPW@|$CONNECTPW|" \
        -e "s|@ENABLEPW@|$ENABLEPW|" -e "s|@SESSIONS@|$SESSIONS|" "$DIR/mill.ini"
    if [ "$(id -u)" = 0 ]; then
        chown -R "$RUN_UID:$RUN_GID" "$DIR" || die "cannot chown $DIR to $SIM_USER"
    fi
    chmod 700 "$DIR"
    fifo_dir_ready
    as_user test -w "$DIR" -a -x "$DIR" || die "$SIM_USER cannot write $DIR (is a parent folder closed to it?)"

    # LinuxCNC: the linuxcnc script, -r keeps its output in our log (no tty, no X)
    ( cd "$DIR" && exec setsid "${AS_USER[@]}" env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME="$DIR" RTAPI_FIFO_PATH="$FIFO" \
        LANG=C.UTF-8 LC_ALL=C.UTF-8 USER="$SIM_USER" LOGNAME="$SIM_USER" TMPDIR="$DIR" \
        LCNC_SIM_DIR="$DIR" linuxcnc -r "$DIR/mill.ini" ) > "$DIR/linuxcnc.log" 2>&1 < /dev/null &
    local lpid=$!
    echo "$lpid" > "$DIR/linuxcnc.pid"

    local deadline ok=0
    deadline=$(( $(date +%s) + START_TIMEOUT ))
    while [ "$(date +%s)" -lt "$deadline" ]; do
        if ! kill -0 "$lpid" 2>/dev/null; then break; fi
        if [ -n "$(ps -C linuxcncrsh -o pid= 2>/dev/null)" ] && hello_ok; then ok=1; break; fi
        sleep 0.1
    done
    if [ "$ok" != 1 ]; then
        if kill -0 "$lpid" 2>/dev/null; then
            echo "$PROG: LinuxCNC did not answer on port $PORT within $START_TIMEOUT s" >&2
        else
            echo "$PROG: LinuxCNC exited while starting" >&2
        fi
        echo "----- $DIR/linuxcnc.log" >&2; cat "$DIR/linuxcnc.log" >&2 2>/dev/null
        for f in "$DIR/linuxcnc_debug.txt" "$DIR/linuxcnc_print.txt"; do
            [ -s "$f" ] && { echo "----- $f" >&2; cat "$f" >&2; }
        done
        STOP_TIMEOUT=0 cmd_stop > /dev/null
        exit 1
    fi

    # ground truth recorder (the sampler FIFO holds 30 s, so nothing since the servo thread
    # started is lost)
    ( cd "$DIR" && exec setsid "${AS_USER[@]}" env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME="$DIR" RTAPI_FIFO_PATH="$FIFO" \
        LANG=C.UTF-8 LC_ALL=C.UTF-8 LCNC_SIM_DIR="$DIR" halsampler -t "$DIR/samples.txt" ) \
        > "$DIR/halsampler.log" 2>&1 < /dev/null &
    local spid=$!
    echo "$spid" > "$DIR/halsampler.pid"

    local rshpid; rshpid="$(ps -C linuxcncrsh -o pid= | tr -d ' ' | head -1)"
    {
        echo "port=$PORT"
        echo "name=$NAME"
        echo "connectpw=$CONNECTPW"
        echo "enablepw=$ENABLEPW"
        echo "linuxcnc_pid=$lpid"
        echo "linuxcncrsh_pid=$rshpid"
        echo "halsampler_pid=$spid"
        echo "loopback_only=$LOOPBACK_ONLY"
        echo "dir=$DIR"
        echo "samples=$DIR/samples.txt"
        echo "log=$DIR/linuxcnc.log"
        echo "start_seconds=$(elapsed "$t0")"
    } | tee "$DIR/sim.env"
}

kill_instance() {   # SIGKILL every process of the instance, wait until gone (max 5 s)
    local pids i
    for i in $(seq 50); do
        pids="$(instance_pids)"
        [ -z "$pids" ] && return 0
        kill -KILL $pids 2>/dev/null || true
        sleep 0.1
    done
    pids="$(instance_pids)"
    [ -z "$pids" ] || { echo "$PROG: processes $pids of $DIR would not die" >&2; return 1; }
}

cmd_stop() {
    local t0 pids rsh p lpid="" deadline; t0="$(now)"
    [ -f "$DIR/linuxcnc.pid" ] && lpid="$(cat "$DIR/linuxcnc.pid")"
    pids="$(instance_pids)"
    if [ -n "$pids" ] && [ "$STOP_TIMEOUT" != 0 ]; then
        # orderly: linuxcncrsh is the display; when it exits the linuxcnc script cleans up
        rsh=""
        for p in $pids; do [ "$(cat /proc/$p/comm 2>/dev/null)" = linuxcncrsh ] && rsh="$rsh $p"; done
        if [ -n "$rsh" ]; then
            kill -TERM $rsh 2>/dev/null || true
            deadline=$(( $(date +%s) + STOP_TIMEOUT ))
            while [ "$(date +%s)" -lt "$deadline" ]; do
                pids="$(instance_pids)"
                # done when only halsampler (or nothing) is left
                local left=""
                for p in $pids; do [ "$(cat /proc/$p/comm 2>/dev/null)" != halsampler ] && left="$left $p"; done
                [ -z "$left" ] && break
                sleep 0.1
            done
        fi
    fi
    # halsampler: TERM so it flushes what it has, then anything left is killed
    for p in $(instance_pids); do
        [ "$(cat /proc/$p/comm 2>/dev/null)" = halsampler ] && kill -TERM "$p" 2>/dev/null
    done
    sleep 0.2
    kill_instance || true
    [ -n "$lpid" ] && wait "$lpid" 2>/dev/null
    cleanup_host_state
    firewall_off
    rm -f "$DIR/linuxcnc.pid" "$DIR/halsampler.pid"
    if [ -n "$(instance_pids)" ]; then echo "$PROG: stop failed, processes left: $(instance_pids)" >&2; exit 1; fi
    echo "stop_seconds=$(elapsed "$t0")"
}

# Prints when the SIGKILL was sent, as cmd_estop says when the pin was set, and for its reason.
cmd_kill() {
    local pids keep="" p t0 t1
    pids="$(instance_pids)"
    [ -n "$pids" ] || { echo "$PROG: nothing runs in $DIR" >&2; return 0; }
    local victims=""
    for p in $pids; do
        if [ "$(cat /proc/$p/comm 2>/dev/null)" = halsampler ]; then keep="$keep $p"; else victims="$victims $p"; fi
    done
    # $EPOCHREALTIME has the locale's decimal separator: a point whatever the locale.
    t0=${EPOCHREALTIME/[!0-9]/.}
    [ -n "$victims" ] && kill -KILL $victims 2>/dev/null
    t1=${EPOCHREALTIME/[!0-9]/.}
    # let halsampler drain the FIFO (the servo thread died with rtapi_app), then stop it
    sleep 0.5
    [ -n "$keep" ] && kill -TERM $keep 2>/dev/null
    sleep 0.2
    kill_instance
    echo "killed=$(echo $victims $keep) kill_between=$t0,$t1"
}

halcmd_as_user() { as_user halcmd "$@"; }

# Prints when halcmd set the pin (between its start and its return, CLOCK_REALTIME seconds): the
# instance look-up before it takes 0.15 s on a quiet machine and over a second on a loaded one, so
# the moment the button was pressed is this, not the command's start.
cmd_estop() {
    local value t0
    case "${1:-press}" in
        press|on) value=0 ;;
        release|off) value=1 ;;
        *) die "estop DIR [press|release]" ;;
    esac
    # $EPOCHREALTIME has the locale's decimal separator: a point whatever the locale.
    t0=${EPOCHREALTIME/[!0-9]/.}
    halcmd_as_user sets estop-ext-ok "$value" || return
    echo "estop-ext-ok=$value set_between=$t0,${EPOCHREALTIME/[!0-9]/.}"
}

cmd_ferror() {
    if [ "${1:-}" = reset ]; then
        halcmd_as_user setp limit3.0.maxv 6 && halcmd_as_user setp limit3.1.maxv 6 && halcmd_as_user setp limit3.2.maxv 6
        return
    fi
    local j="${1:-0}" v="${2:-0.5}"
    [[ "$j" =~ ^[012]$ ]] || die "ferror DIR [JOINT 0|1|2 [MAXV]] | ferror DIR reset"
    halcmd_as_user setp "limit3.$j.maxv" "$v"
}

case "$CMD" in
    start) cmd_start ;;
    stop) cmd_stop ;;
    status)
        pids="$(instance_pids | tr '\n' ' ')"
        if [ -n "$pids" ]; then echo "running pids=$pids"; exit 0; else echo "stopped"; exit 1; fi ;;
    estop) [ -n "$(instance_pids)" ] || die "nothing runs in $DIR"; cmd_estop "$@" ;;
    ferror) [ -n "$(instance_pids)" ] || die "nothing runs in $DIR"; cmd_ferror "$@" ;;
    kill) cmd_kill ;;
    hal) [ -n "$(instance_pids)" ] || die "nothing runs in $DIR"; halcmd_as_user "$@" ;;
    *) usage >&2; exit 64 ;;
esac
