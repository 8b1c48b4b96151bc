"""Cache keys of rendered handover videos: what determines a video's pixels, hashed."""

from __future__ import annotations

import functools
import hashlib
import inspect
import json
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

RenderFn = Callable[..., Path]
"""``render_fn(robot, behavior, scene, out_path, seed=0, width=..., height=..., fps=...,
progress=True) -> Path`` (size and rate default to
:data:`gazebot.apps.render.video_settings.VIDEO`): the contract of
``gazebot.apps.render.video.render_handover_video``. It must be
picklable (a module-level function or a ``functools.partial`` of one) to run in workers."""


@dataclass(frozen=True)
class VideoSpec:
    """One handover video. ``inputs``: a digest of the behavior's, scene's and robot's content
    (:func:`inputs_digest`), so an edited YAML gets a new video although its name is the same."""

    robot: str
    behavior: str
    scene: str
    seed: int
    width: int
    height: int
    fps: int
    gaze_mode: str = "head-and-eyes"
    inputs: str = ""

    def content_hash(self, code_version: str) -> str:
        """Hash of everything that determines the video's pixels."""
        blob = json.dumps({**asdict(self), "code": code_version}, sort_keys=True)
        return hashlib.sha256(blob.encode()).hexdigest()[:16]

    def file_name(self, code_version: str) -> str:
        return (
            f"{self.robot}_{self.behavior}_{self.scene}_s{self.seed}_"
            f"{self.content_hash(code_version)}.mp4"
        )


def behavior_content(behavior: str) -> str:
    """The resolved content of behavior ``behavior`` (a name in the built-in or user folders, or
    a YAML path) as canonical JSON, ``extends:`` chains included; ``""`` if it cannot be loaded
    (the renderer reports that error itself)."""
    from gazebot.core.behaviors import load_behavior

    try:
        spec = load_behavior(behavior)
    except (FileNotFoundError, ValueError):
        return ""
    return json.dumps(spec.model_dump(mode="json"), sort_keys=True)


def _config_bytes(kind: str, name: str) -> bytes:
    """The bytes of config ``configs/<kind>/<name>.yaml`` or of the file ``name``; empty if
    neither exists."""
    from gazebot.core.config import configs_dir

    candidates = [Path(name)] if name.endswith((".yaml", ".yml")) else []
    try:
        candidates.append(configs_dir() / kind / f"{name}.yaml")
    except FileNotFoundError:
        pass  # no configs folder (an installed wheel without it): only the file itself
    for path in candidates:
        if path.is_file():
            return path.read_bytes()
    return b""


def inputs_digest(robot: str, behavior: str, scene: str) -> str:
    """A digest of what the names ``robot``, ``behavior`` and ``scene`` stand for today: the
    behavior's resolved content and the scene's and robot's files."""
    h = hashlib.sha256()
    h.update(behavior_content(behavior).encode())
    h.update(b"\0" + _config_bytes("scenes", scene))
    h.update(b"\0" + _config_bytes("robots", robot))
    return h.hexdigest()[:16]


def _files_digest(paths: Iterable[Path], root: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(paths):
        h.update(str(p.relative_to(root)).encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def code_version(render_fn: RenderFn) -> str:
    """A fingerprint of the code and data behind ``render_fn``'s output.

    For gazebot's own renderers: the package version plus the contents of the package's sources,
    assets and ``configs/`` (excluding the study and CLI modules, which do not change pixels); for
    any other function: its qualified name and its module's source.
    """
    fn = render_fn.func if isinstance(render_fn, functools.partial) else render_fn
    module = inspect.getmodule(fn)
    name = f"{getattr(module, '__name__', '?')}.{getattr(fn, '__qualname__', repr(fn))}"
    if isinstance(render_fn, functools.partial):
        name += repr(sorted(render_fn.keywords.items()))
    if name.startswith("gazebot."):
        import gazebot
        from gazebot.core.config import configs_dir

        pkg = Path(gazebot.__file__).resolve().parent
        files = [
            p
            for p in pkg.rglob("*")
            if p.is_file()
            and p.suffix in {".py", ".xml", ".yaml", ".yml", ".png", ".stl", ".obj"}
            and not ({"study", "cli", "__pycache__"} & set(p.relative_to(pkg).parts))
        ]
        # The study package is excluded above, so a renderer living there is hashed by itself.
        digest = _module_digest(fn, module) if module and "study" in name.split(".") else ""
        digest += _files_digest(files, pkg)
        try:
            cfg = configs_dir()
            digest += _files_digest([p for p in cfg.rglob("*") if p.is_file()], cfg)
        except FileNotFoundError:
            pass  # no configs folder: the key covers the code alone
        return f"{name}@{getattr(gazebot, '__version__', '0')}:{digest[:16]}"
    return f"{name}:{_module_digest(fn, module)}"


def _module_digest(fn: Callable, module: object) -> str:
    try:
        src = inspect.getsource(module) if module else repr(fn)  # type: ignore[arg-type]
    except (OSError, TypeError):
        src = repr(fn)
    return hashlib.sha256(src.encode()).hexdigest()[:16]
