"""Check that MuJoCo can render off-screen (EGL, else OSMesa) and say what to install if not.

``python -m gazebot.apps.render.gl_check`` prints the working back end (exit 0) or the Debian/Ubuntu
packages to install (exit 1). ``ensure_gl_backend()`` picks a working back end for this process
when ``MUJOCO_GL`` is unset; call it before MuJoCo is imported.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys

BACKENDS = ("egl", "osmesa")
PACKAGES = {"egl": "libegl1 (plus libgl1 / libgles2 for your GPU or Mesa)", "osmesa": "libosmesa6"}

_PROBE = """
import mujoco, numpy as np
m = mujoco.MjModel.from_xml_string(
    '<mujoco><visual><global offwidth="64" offheight="64"/></visual><worldbody>'
    '<light pos="0 0 1"/><geom type="sphere" size=".1" rgba="1 0 0 1"/></worldbody></mujoco>')
d = mujoco.MjData(m)
with mujoco.Renderer(m, 64, 64) as r:
    mujoco.mj_forward(m, d)
    r.update_scene(d)
    img = r.render()
assert img.shape == (64, 64, 3) and img.any()
"""


def probe(backend: str, timeout: float = 60.0) -> tuple[bool, str]:
    """Render a tiny scene with ``MUJOCO_GL=backend`` in a child process; (ok, error text)."""
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    try:
        proc = subprocess.run(
            [sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        return False, f"timed out after {timeout:.0f} s"
    lines = proc.stderr.strip().splitlines()
    return proc.returncode == 0, lines[-1] if lines else ""


class OffscreenRenderingError(RuntimeError):
    """MuJoCo could not render off-screen; the message says what to install or set."""


def ensure_gl_backend(probe_first: bool = True) -> str:
    """Choose MuJoCo's GL back end for this process before MuJoCo is imported.

    Uses ``MUJOCO_GL`` if set. Otherwise, with ``probe_first``, the first working of EGL and OSMesa
    (a child process renders a tiny scene, ~1 s); without it, EGL. Sets ``MUJOCO_GL`` (and
    ``PYOPENGL_PLATFORM``) for this process and returns the choice.

    Raises:
        OffscreenRenderingError: probing found no working back end (the message names the
            packages to install).
        ModuleNotFoundError: MuJoCo is not installed (the ``sim`` extra), which no system
            package fixes.
    """
    chosen = os.environ.get("MUJOCO_GL")
    if chosen:
        return chosen
    if "mujoco" in sys.modules:  # too late to choose: MuJoCo picked its back end on import
        return "default"
    if importlib.util.find_spec("mujoco") is None:
        raise ModuleNotFoundError("No module named 'mujoco'", name="mujoco")
    if not sys.platform.startswith("linux"):  # macOS/Windows: MuJoCo's own default works
        return "default"
    errors = {}
    for backend in BACKENDS if probe_first else BACKENDS[:1]:
        ok, err = probe(backend) if probe_first else (True, "")
        if ok:
            os.environ["MUJOCO_GL"] = backend
            os.environ.setdefault("PYOPENGL_PLATFORM", backend)
            return backend
        errors[backend] = err
    raise OffscreenRenderingError(_help(errors))


def explain_failure(exc: BaseException) -> OffscreenRenderingError:
    """Turn a GL error from MuJoCo into an error that says what to do."""
    backend = os.environ.get("MUJOCO_GL", "<unset>")
    return OffscreenRenderingError(_help({backend: f"{type(exc).__name__}: {exc}"}))


def _help(errors: dict[str, str]) -> str:
    lines = ["MuJoCo cannot render off-screen (needed for the demo video)."]
    lines += [f"  {b}: {e or 'failed'}" for b, e in errors.items()]
    lines.append("Install one of these system packages and retry, e.g. on Debian/Ubuntu:")
    lines.append("  sudo apt-get install libegl1        # EGL (preferred; GPU or Mesa)")
    lines.append("  sudo apt-get install libosmesa6     # OSMesa (software fallback)")
    lines.append("then run with MUJOCO_GL=egl or MUJOCO_GL=osmesa")
    lines.append("(check with: python -m gazebot.apps.render.gl_check).")
    return "\n".join(lines)


def main() -> int:
    requested = os.environ.get("MUJOCO_GL")
    order = (requested,) if requested else BACKENDS
    errors = {}
    for backend in order:
        ok, err = probe(backend)
        if ok:
            print(f"gl_check: MuJoCo off-screen rendering works with MUJOCO_GL={backend}")
            return 0
        errors[backend] = err
    if requested and requested not in BACKENDS:
        print(f"gl_check: MUJOCO_GL={requested} does not work; try egl or osmesa", file=sys.stderr)
    print(_help(errors), file=sys.stderr)
    print("Packages: " + "; ".join(f"{b}: {p}" for b, p in PACKAGES.items()), file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
