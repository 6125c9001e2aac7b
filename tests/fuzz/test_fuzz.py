"""Mutated manifests and scenes never end in a traceback, a hang or an unlocated error.

Hypothesis draws a seed from robots/ and one to three mutations (the campaign's mutators,
:mod:`tests.fuzz.mutators`), and the case runs in this process through the real stages
(:mod:`tests.fuzz.stages`): load, ``robot check`` and the bare-robot HAL for manifests;
load and the scene HAL for scenes. Robosuite scenes are only loaded here (their build
takes about 2 s); ``just fuzz N`` builds them too. About 60 s on two cores; there is no
shrinking phase, since shrinking a slow case could take minutes: a failure prints the
drawn case and a ``python -m tests.fuzz.replay --spec`` command that reruns it.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from tests.fuzz.cases import CaseSpec, write_case
from tests.fuzz.mutators import MUTATOR_NAMES
from tests.fuzz.outcome import FINDINGS, HANG_SECONDS
from tests.fuzz.seeds import seeds
from tests.fuzz.stages import run_case, time_limit

MAX_EXAMPLES = 600
"""Cases per run: about 60 s on the 2-core CI machine (most end at load in milliseconds;
those that pass it take 0.1-1.5 s each)."""

mutations = st.lists(
    st.tuples(st.sampled_from(MUTATOR_NAMES), st.integers(0, 2**32 - 1)), min_size=1, max_size=3
).map(tuple)
cases = st.builds(CaseSpec, st.sampled_from([seed.name for seed in seeds()]), mutations)


@settings(
    max_examples=MAX_EXAMPLES,
    deadline=None,
    phases=(Phase.explicit, Phase.reuse, Phase.generate),
    suppress_health_check=[HealthCheck.too_slow],
    print_blob=True,
)
@given(spec=cases)
def test_mutated_file_is_accepted_or_refused_with_its_location(spec: CaseSpec) -> None:
    with tempfile.TemporaryDirectory(prefix="openral-fuzz-") as folder:
        case = write_case(spec, Path(folder), load_only_slow=True)
        with time_limit(HANG_SECONDS * 2):
            result = run_case(case)
    replay = f"python -m tests.fuzz.replay --spec '{json.dumps(spec.to_json())}'"
    assert result.outcome not in FINDINGS, (
        f"{result.outcome} in stage {result.stage}: {result.signature}\n"
        f"{result.detail}\nrerun: {replay}"
    )
