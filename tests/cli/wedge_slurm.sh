# `gale wedge --farm slurm` on a real Slurm cluster: a private single-node cluster (Debian's
# slurmctld, slurmd and munge, installed here when missing, as root) in a temporary folder, with
# SLURM_CONF at a generated slurm.conf (proctrack/linuxproc, task/none, a private munge socket,
# no cgroup.conf). A 4-variant wedge is submitted with --submit and checked (frames, --status);
# then one task is cancelled mid-run (scancel), the array re-submitted, and the variant resumes
# without recomputing its finished frames (their inodes and times unchanged). Every daemon is
# stopped by pid. Skips (exit 0, with a message) only where Slurm cannot be installed or run.
source "$(dirname "$0")/lib.bash" "$@"

skip() {
    echo "SKIP: $*"
    exit 0
}
die() {
    fail "$*"
    finish
}
need=()
for b in slurmctld:slurmctld slurmd:slurmd munged:munge sbatch:slurm-client; do
    command -v "${b%%:*}" > /dev/null || [ -x "/usr/sbin/${b%%:*}" ] || need+=("${b##*:}")
done
if [ ${#need[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get > /dev/null; then
        echo "installing ${need[*]}" >&2
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${need[@]}" > apt.log 2>&1 ||
            { apt-get update -qq > /dev/null 2>&1 &&
              DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${need[@]}" > apt.log 2>&1; } ||
            skip "cannot install ${need[*]}: $(tail -n 1 apt.log)"
    else
        skip "Slurm (${need[*]}) is not installed and cannot be installed here (not root, or no apt)"
    fi
fi
[ "$(id -u)" = 0 ] || skip "the private cluster runs its daemons as root"
export PATH=$PATH:/usr/sbin

# ---- the cluster ----
C=$TMP/cluster
mkdir -p "$C/state" "$C/spool"
chmod 700 "$C"
PIDS=()
stop_all() {
    local p
    for p in "${PIDS[@]}"; do kill "$p" 2> /dev/null; done
    for p in "${PIDS[@]}"; do
        for _ in $(seq 1 100); do kill -0 "$p" 2> /dev/null || break; sleep 0.05; done
        kill -9 "$p" 2> /dev/null
    done
    rm -rf "$TMP"
}
trap stop_all EXIT
trap 'exit 1' TERM INT HUP

head -c 1024 /dev/urandom > "$C/munge.key"
chmod 400 "$C/munge.key"
munged -F --force --key-file="$C/munge.key" --socket="$C/munge.sock" --pid-file="$C/munged.pid" \
    --log-file="$C/munged.log" --seed-file="$C/munged.seed" 2> "$C/munged.err" &
PIDS+=($!)
wait_file "$C/munge.sock" "${PIDS[0]}" || die "munged does not start: $(cat "$C/munged.err" "$C/munged.log" 2> /dev/null | tail -n 3)"

ports=($(/usr/bin/python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])'))
export SLURM_CONF=$C/slurm.conf
cat > "$SLURM_CONF" <<CONF
ClusterName=galetest
SlurmctldHost=$(hostname -s)(127.0.0.1)
MailProg=/bin/true
MessageTimeout=5
SlurmctldPort=${ports[0]}
SlurmdPort=${ports[1]}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$C/munge.sock
StateSaveLocation=$C/state
SlurmdSpoolDir=$C/spool
SlurmctldPidFile=$C/slurmctld.pid
SlurmdPidFile=$C/slurmd.pid
SlurmctldLogFile=$C/slurmctld.log
SlurmdLogFile=$C/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=galenode NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=gale Nodes=galenode Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -D -i > "$C/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -N galenode > "$C/slurmd.out" 2>&1 &
PIDS+=($!)
up=""
state=""
for _ in $(seq 1 150); do
    kill -0 "${PIDS[1]}" 2> /dev/null && kill -0 "${PIDS[2]}" 2> /dev/null || break
    state=$(timeout 5 sinfo -h -N -o %T 2> /dev/null)
    case "$state" in idle*) up=1; break ;; esac
    sleep 0.2
done
[ -n "$up" ] || die "the private cluster does not come up (node state '$state'): $(tail -n 3 "$C/slurmctld.out" "$C/slurmd.out" 2> /dev/null)"

# wait_job ID: until the job (every array task) has left the queue (at most about 100 s).
wait_job() {
    for _ in $(seq 1 1000); do
        [ -z "$(timeout 5 squeue -h -j "$1" 2> /dev/null)" ] && return 0
        sleep 0.1
    done
    fail "job $1 still queued after 100 s: $(squeue -j "$1")"
    return 1
}

tiny_scene 24 12 4 > tiny.toml

# ---- a 4-variant wedge, submitted ----
run "$GALE" wedge tiny.toml --vary cloth.c.lift=0.1,0.3 --vary cloth.c.drag=0.8,1.2 -o w --farm slurm --submit \
    --partition gale --cache mdd
expect_rc 0 "wedge --farm slurm --submit ($ERR)"
job=$OUT
expect_match "$job" '^[0-9]+$' "prints the job id"
[ -f w/submit.sbatch ] || fail "writes w/submit.sbatch"
expect_match "$(cat w/submit.sbatch)" '^#SBATCH --array=1-4$' "an array over the 4 lines of tasks.txt"
expect_match "$(cat w/submit.sbatch)" '^#SBATCH --requeue$' "requeue-safe"
wait_job "$job"
for d in w/v00*/; do
    [ -f "$d/DONE" ] || fail "$d finished on the cluster ($(cat "$d/log.txt" 2> /dev/null | tail -n 2))"
    for f in $(seq -f %04g 1 24); do [ -s "$d/c.$f.obj" ] || { fail "$d/c.$f.obj"; break; }; done
    # --cache mdd reaches the tasks: a 24-frame cache of the 144 vertices (big-endian header).
    expect_eq "$(od -An -tx1 -N8 "$d/c.mdd" 2> /dev/null | tr -d ' \n')" "0000001800000090" "$d/c.mdd header"
done
expect_eq "$(ls w/logs | wc -l)" "4" "one log per task in w/logs"
expect_match "$(cat w/logs/${job}_1.out)" "gale wedge: task 1 on" "the task log names the task"
run "$GALE" wedge --status w
expect_rc 0 "--status"
expect_eq "$(grep -c ' done (24 frames)' <<< "$OUT")" "4" "--status: every variant done ($OUT)"
expect_match "$OUT" "^4 done, 0 partial, 0 failed, 0 not started$" "--status summary"

# ---- cancel one task mid-run, re-submit: it resumes ----
run "$GALE" wedge tiny.toml --vary cloth.c.lift=0.1,0.3 --vary cloth.c.drag=0.8,1.2 -o w2 --farm slurm --submit \
    --frames 1:400
expect_rc 0 "second wedge submitted ($ERR)"
job2=$OUT
v=$(ls -d w2/v000_*)
wait_file "$v/c.0030.obj" || true
for _ in $(seq 1 400); do [ -f "$v/c.0030.obj" ] && break; sleep 0.05; done
[ -f "$v/c.0030.obj" ] || fail "the first task writes frames"
scancel "${job2}_1"
for _ in $(seq 1 200); do
    [ -z "$(timeout 5 squeue -h -j "${job2}_1" 2> /dev/null)" ] && break
    sleep 0.05
done
sleep 0.3
[ -f "$v/DONE" ] && fail "the cancelled task did not finish"
run "$GALE" wedge --status w2
expect_match "$OUT" "^v000_[^ ]*  partial \([0-9]+ of 400 frames\)" "--status: the cancelled variant is partial ($OUT)"
have=$(ls "$v"/c.*.obj | wc -l)
declare -A stamp
for f in "$v"/c.*.obj; do stamp[$f]=$(stat -c '%i %Y.%y' "$f"); done
wait_job "$job2"
run "$GALE" wedge tiny.toml --vary cloth.c.lift=0.1,0.3 --vary cloth.c.drag=0.8,1.2 -o w2 --farm slurm --submit \
    --frames 1:400
expect_rc 0 "re-submitted"
job3=$OUT
wait_job "$job3"
[ -f "$v/DONE" ] || fail "the cancelled variant completes after re-submission ($(tail -n 3 "$v/log.txt"))"
expect_match "$(cat "$v/log.txt")" "resuming after frame" "it resumed instead of starting over"
changed=0
for f in "${!stamp[@]}"; do [ "$(stat -c '%i %Y.%y' "$f")" = "${stamp[$f]}" ] || changed=$((changed + 1)); done
# The frame being written when the task was cancelled may be rewritten: at most one.
[ "$changed" -le 1 ] || fail "$changed of $have finished frames were recomputed"
for d in w2/v00*/; do [ -f "$d/DONE" ] || fail "$d done after re-submission"; done
run "$GALE" wedge --status w2
expect_match "$OUT" "^4 done, 0 partial, 0 failed, 0 not started$" "--status after the re-submission ($OUT)"
finish
