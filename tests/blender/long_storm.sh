#!/bin/sh
# The long storm (`make storm`, not part of `make test`): tests/blender/storm.py's seeded random
# sequences of artist operations, 400 steps each, checked after every step; seeds 1-10 on the
# newest Blender line, seeds 11-13 on Debian's Blender and the other bpy lines. A failing seed
# prints the shortest sequence of steps that still fails.
cd "$(dirname "$0")/../.." || exit 2
export CCN_CASES=case_storm CCN_STORM_STEPS=${CCN_STORM_STEPS:-400}
export CCN_BLENDER_TIMEOUT=${CCN_BLENDER_TIMEOUT:-7200}
newest=${CCN_STORM_NEWEST:-5.3}
others=${CCN_STORM_OTHERS:-"4.2 4.5 5.2"}
rc=0
CCN_STORM_SEEDS=${CCN_STORM_SEEDS_NEWEST:-1,2,3,4,5,6,7,8,9,10} CCN_DEBIAN=0 CCN_BPY_LINES=$newest \
  sh tests/blender/run_blender.sh || rc=1
CCN_STORM_SEEDS=${CCN_STORM_SEEDS_OTHERS:-11,12,13} CCN_BPY_LINES=$others \
  sh tests/blender/run_blender.sh || rc=1
exit $rc
