"""Hypothesis over the YAML loaders (behavior, robot, scene, phases, controllers, eye style):
any file is a loaded config or a one-line :class:`ConfigError` naming the file; no other
exception, no hang, bounded memory."""

from __future__ import annotations

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gazebot.core.config import ConfigError

FUZZ = settings(
    max_examples=30,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)

KEYS = st.sampled_from([
    "name", "segments", "extends", "target", "duration_s", "method", "posture", "object",
    "camera", "azimuth_deg", "controller", "reach_time_s", "mjcf", "head_joints", "eyes",
    "yaw_range_deg", "pupil", "color", "display", "width_px", "giver", "phases", "x", "<<",
])
SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(-(10**20), 10**20),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(KEYS, inner, max_size=4)
    ),
    max_leaves=20,
)
DOCS = st.one_of(
    st.dictionaries(KEYS, VALUES, max_size=6).map(lambda d: yaml.safe_dump(d)),
    st.text(max_size=300),
    st.sampled_from(["a: &x [1]\nb: *x\n", "[" * 500, "{a: 1, a: 2}", "!!python/object:os.system x",
                     "a: !!binary AAAA", "--- 1\n--- 2\n", "\ufeffname: x\n", "a:\n\t- b"]),
)


def _loaders():
    from gazebot.apps.controllers.config import load_controllers_config
    from gazebot.apps.render.eye_style import load_eye_style
    from gazebot.apps.sim.scene_config import load_scene
    from gazebot.core.behaviors.registry import load_behavior
    from gazebot.core.kinematics.robot_config import load_robot_config
    from gazebot.core.phases.config import load_phase_config

    return [load_behavior, load_robot_config, load_scene, load_phase_config,
            load_controllers_config, load_eye_style]


@pytest.mark.timeout(300)
@FUZZ
@given(text=DOCS, raw=st.one_of(st.none(), st.binary(max_size=200)))
def test_any_yaml_file_is_a_config_or_a_one_line_config_error(tmp_path, bounded_memory, text, raw):
    path = tmp_path / "fuzz.yaml"
    path.write_bytes(raw if raw is not None else text.encode("utf-8", "surrogatepass"))
    for load in _loaders():
        with bounded_memory(50e6):
            try:
                load(path)
            except ConfigError as exc:
                msg = str(exc)
                assert msg.startswith(str(path)) and "\n" not in msg, msg


def _shipped():
    """(loader, parsed shipped file) pairs: real configs to mutate one value of."""
    from gazebot.apps.controllers.config import load_controllers_config
    from gazebot.apps.render.eye_style import load_eye_style
    from gazebot.apps.sim.scene_config import load_scene
    from gazebot.core.behaviors.registry import load_behavior
    from gazebot.core.config import configs_dir
    from gazebot.core.phases.config import load_phase_config

    root = configs_dir()
    pairs = [(load_behavior, p) for p in sorted((root / "behaviors").glob("*.yaml"))]
    pairs += [(load_scene, p) for p in sorted((root / "scenes").glob("*.yaml"))]
    pairs += [(load_eye_style, p) for p in sorted((root / "eyes").glob("*.yaml"))]
    pairs += [(load_phase_config, root / "phases.yaml"),
              (load_controllers_config, root / "controllers.yaml")]
    return [(load, yaml.safe_load(p.read_text())) for load, p in pairs]


SHIPPED = _shipped()


def _paths(doc, prefix=()):
    yield prefix
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _paths(v, (*prefix, i))


def _replace(doc, path, value):
    if not path:
        return value
    import copy

    doc = copy.deepcopy(doc)
    node = doc
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return doc


@pytest.mark.timeout(300)
@FUZZ
@given(data=st.data())
def test_a_shipped_config_with_one_value_replaced_is_loaded_or_refused_in_one_line(
    tmp_path, bounded_memory, data
):
    load, doc = data.draw(st.sampled_from(SHIPPED))
    path = data.draw(st.sampled_from(list(_paths(doc))))
    value = data.draw(VALUES)
    mutated = tmp_path / "mutated.yaml"
    mutated.write_text(yaml.safe_dump(_replace(doc, path, value)))
    with bounded_memory(50e6):
        try:
            load(mutated)
        except ConfigError as exc:
            assert str(exc).startswith(str(mutated)) and "\n" not in str(exc)
