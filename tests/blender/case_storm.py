"""A seeded random storm of artist operations (storm.py), checked after every step: every shown
surface equals `ccnurbs limit` of the cage its modifier sees, no traceback, finite coordinates,
nothing unused after a save. `make test` runs a few short storms on every Blender; the long run
(10 seeds x 400 steps on the newest Blender) is `tests/blender/long_storm.sh`. A failing storm
prints the shortest sequence of steps that still fails."""
from bltest import *  # noqa: F401,F403
import storm

SEEDS = [int(s) for s in os.environ.get("CCN_STORM_SEEDS", "1,2").split(",")]
STEPS = int(os.environ.get("CCN_STORM_STEPS", "60"))


class TestStorm(AddonTestCase):
    def test_storm(self):
        s = storm.Storm(ccn, CLI, TMP)
        for seed in SEEDS:
            with self.subTest(seed=seed):
                ops = storm.Storm.plan(seed, STEPS)
                fail = s.run(ops)
                if fail is not None:
                    short, why = s.shortest(ops)
                    self.fail("storm seed %d fails at step %d: %s\nshortest failing sequence (%d "
                              "steps): %s\n  -> %s" % (seed, fail[0], fail[1], len(short),
                                                        short, why[1] if why else "?"))
                print("measure storm: seed %d, %d steps checked" % (seed, len(ops)))
