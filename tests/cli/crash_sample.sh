# `gale sample --frames` killed with SIGKILL part-way (.npy, .csv and .vdb sequences; right after
# frame k appears and at short delays, so some kills land mid-write): every frame on disk is whole
# and equal to an uninterrupted run's, and `--resume` writes only the missing frames, removes the
# killed writers' temporary files and ends with the same sequence byte for byte.
source "$(dirname "$0")/lib.bash" "$@"

EXPR='[sin(3 * $P[0] + $t) * noise($P * 2 + $t), cos(2 * $P[1] - $t), noise($P * 3 - [$t, 0, 0])]'
GRID=(--bounds 0,0,0,2,1,1 --res 48,24,24 --threads 1) # 27648 cells
FRAMES=1:30

# check_seq DIR EXT WHEN: every frame file is whole and identical to the reference's.
check_seq() {
    local dir=$1 ext=$2 when=$3 f name hlen
    for f in "$dir"/g.*."$ext"; do
        [ -e "$f" ] || continue
        name=${f##*/}
        [ -f "ref_$ext/$name" ] || { fail "$when: $name is not a frame of the reference"; continue; }
        case $ext in
            npy)
                # magic, a header naming the shape, then exactly 27648 * 3 float32.
                [ "$(head -c 6 "$f" | tail -c 5)" = "NUMPY" ] || fail "$when: $name magic"
                hlen=$(od -A n -t u2 -j 8 -N 2 "$f" | tr -d ' ')
                head -c $((10 + hlen)) "$f" | grep -q "'shape': (48, 24, 24, 3)" || fail "$when: $name shape"
                expect_eq "$(stat -c %s "$f")" "$((10 + hlen + 27648 * 12))" "$when: $name size" ;;
            csv)
                expect_eq "$(wc -l < "$f")" "27649" "$when: $name rows"
                [ -z "$(tail -c 1 "$f")" ] || fail "$when: $name ends mid-line" ;;
            vdb)
                expect_eq "$(stat -c %s "$f")" "$(stat -c %s "ref_$ext/$name")" "$when: $name size" ;;
        esac
        same "$f" "ref_$ext/$name" || fail "$when: $name differs from the uninterrupted run"
    done
}

# same A B: byte for byte, except that OpenVDB gives every file a random UUID (36 characters
# at offset 21 of the header), which is skipped for .vdb files.
same() {
    case $1 in
        *.vdb) cmp -s -n 21 "$1" "$2" && cmp -s -i 57 "$1" "$2" &&
            head -c 57 "$1" | tail -c 36 | grep -Eq '^[0-9a-f]{8}-([0-9a-f]{4}-){3}[0-9a-f]{12}$' ;;
        *) cmp -s "$1" "$2" ;;
    esac
}

KILLS=0
MID_WRITE=0
for ext in npy csv vdb; do
    mkdir "ref_$ext" "run_$ext"
    run "$GALE" sample -e "$EXPR" "${GRID[@]}" --frames $FRAMES -o "ref_$ext/g.#.$ext"
    expect_rc 0 "$ext: the uninterrupted reference"
    expect_eq "$(ls "ref_$ext" | wc -l)" "30" "$ext: thirty frames"

    RANDOM=$((${#ext} + 5)) # fixed seed per format: the same delays every time
    for when in 0003 0009 0016 0022 d d d d; do
        "$GALE" sample -e "$EXPR" "${GRID[@]}" --frames $FRAMES -o "run_$ext/g.#.$ext" --resume 2> /dev/null &
        pid=$!
        if [ "$when" = d ]; then
            sleep "0.0$((RANDOM % 10))$((RANDOM % 10))"
        else
            wait_file "run_$ext/g.$when.$ext" "$pid"
        fi
        kill -KILL "$pid" 2> /dev/null && KILLS=$((KILLS + 1))
        wait "$pid" 2> /dev/null
        compgen -G "run_$ext/*.tmp.*" > /dev/null && MID_WRITE=$((MID_WRITE + 1))
        check_seq "run_$ext" "$ext" "$ext: killed at $when"
    done

    # A dead writer's temporary file is removed by the resume; other files are left alone.
    sleep 0 &
    dead=$!
    wait "$dead"
    printf 'half' > "run_$ext/g.0030.$ext.tmp.$dead"
    printf 'keep' > "run_$ext/other.tmp.$dead"
    on_disk=$(ls "run_$ext" | grep -c "^g\.[0-9]*\.$ext$")
    run "$GALE" sample -e "$EXPR" "${GRID[@]}" --frames $FRAMES -o "run_$ext/g.#.$ext" --resume
    expect_rc 0 "$ext: resume"
    if [ "$on_disk" -gt 0 ]; then
        expect_match "$ERR" "--resume: $on_disk of 30 frame\(s\) already on disk, skipped" "$ext: skips what is there"
    fi
    check_seq "run_$ext" "$ext" "$ext: after --resume"
    expect_eq "$(ls "run_$ext" | grep -c "^g\.[0-9]*\.$ext$")" "30" "$ext: every frame after --resume"
    expect_eq "$(ls "run_$ext" | grep tmp | tr '\n' ' ')" "other.tmp.$dead " "$ext: only the foreign temporary file is left"
done
[ "$KILLS" -ge 12 ] || fail "most runs were killed before they finished ($KILLS kills)"
echo "crash_sample: $KILLS kills, $MID_WRITE left a temporary file behind" >&2

# --resume belongs to --frames.
run "$GALE" sample -e "$EXPR" "${GRID[@]}" -o one.npy --resume
expect_rc 2 "--resume without --frames"
expect_match "$ERR" "--resume continues a --frames sequence" "says why"
finish
