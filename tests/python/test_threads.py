# One compiled expression evaluated from 8 Python threads at once gives what one thread gives
# (the GIL is released during eval; timing is in bench/python_eval.py, not here).
import threading

import numpy as np

import gale


def test_eight_threads_one_program():
    e = gale.compile(source="$s = 3; # 0, 10\n$s * fbm($P + [0, 0, $t]) * [1, 0.5, 0.25] + curlnoise($P * 0.5)")
    rng = np.random.default_rng(3)
    inputs = [rng.uniform(-4, 4, size=(20000, 3)) for _ in range(8)]
    want = [e.eval(P, t=0.1 * i, params={"s": i + 1.0}, threads=1) for i, P in enumerate(inputs)]
    got = [None] * 8
    errors = []
    start = threading.Barrier(8)

    def work(i):
        try:
            start.wait()
            for _ in range(3):
                got[i] = e.eval(inputs[i], t=0.1 * i, params={"s": i + 1.0}, threads=1)
        except Exception as x:  # reported below: an exception in a thread does not fail the test
            errors.append(x)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)
