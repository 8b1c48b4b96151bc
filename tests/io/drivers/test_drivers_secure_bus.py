"""A secured bus (issue 21): ``--zenoh-config FILE`` on every node, so Zenoh's TLS (here mutual
TLS with a certificate authority the test makes) keeps out a node without the certificate."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from drivers_fakes import free_port, wait_until

from gazebot.apps.cli import main
from gazebot.io.drivers.session import BusConfig, open_session

ROOT = Path(__file__).resolve().parents[3]


def _openssl(*args: str, cwd: Path) -> None:
    subprocess.run(["openssl", *args], cwd=cwd, check=True, capture_output=True)


def make_ca_and_cert(folder: Path, name: str) -> dict[str, str]:
    """A self-signed CA and a certificate for localhost / 127.0.0.1 (server and client use)
    signed by it, made with the openssl command line: paths of ``ca``, ``cert``, ``key``."""
    folder.mkdir(parents=True, exist_ok=True)
    _openssl("req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes",
             "-keyout", "ca.key", "-out", "ca.pem", "-days", "2", "-subj", f"/CN={name} CA",
             cwd=folder)
    _openssl("req", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes",
             "-keyout", "node.key", "-out", "node.csr", "-subj", "/CN=localhost", cwd=folder)
    (folder / "ext.cnf").write_text(
        "subjectAltName=DNS:localhost,IP:127.0.0.1\nbasicConstraints=CA:FALSE\n"
        "keyUsage=digitalSignature\nextendedKeyUsage=serverAuth,clientAuth\n")
    _openssl("x509", "-req", "-in", "node.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
             "-CAcreateserial", "-out", "node.pem", "-days", "2", "-extfile", "ext.cnf",
             cwd=folder)
    return {k: str(folder / f) for k, f in
            (("ca", "ca.pem"), ("cert", "node.pem"), ("key", "node.key"))}


def tls_config(path: Path, pki: dict[str, str]) -> Path:
    """A Zenoh JSON5 configuration with mutual TLS: the node presents ``pki``'s certificate
    and accepts only peers whose certificate ``pki``'s CA signed."""
    tls = {"root_ca_certificate": pki["ca"], "listen_certificate": pki["cert"],
           "listen_private_key": pki["key"], "connect_certificate": pki["cert"],
           "connect_private_key": pki["key"], "enable_mtls": True}
    path.write_text("// gazebot test: mutual TLS\n" + json.dumps(
        {"transport": {"link": {"tls": tls}}}, indent=2))
    return path


@pytest.fixture
def pki(tmp_path):
    if shutil.which("openssl") is None:
        pytest.skip("openssl command not found (needed to make the test's certificates)")
    return make_ca_and_cert(tmp_path / "pki", "gazebot"), make_ca_and_cert(tmp_path / "other",
                                                                           "intruder")


def test_a_zenoh_config_file_is_the_base_and_gazebot_sets_its_endpoints(tmp_path, pki):
    good, _ = pki
    path = tls_config(tmp_path / "tls.json5", good)
    cfg = BusConfig(listen=("tls/localhost:7447",), config_file=str(path)).zenoh_config()
    assert json.loads(cfg.get_json("transport/link/tls/root_ca_certificate")) == good["ca"]
    assert json.loads(cfg.get_json("transport/link/tls/enable_mtls")) is True
    assert json.loads(cfg.get_json("listen/endpoints")) == ["tls/localhost:7447"]
    assert json.loads(cfg.get_json("scouting/multicast/enabled")) is False  # gazebot's default


def test_a_bad_zenoh_config_file_is_a_one_line_error_naming_it(tmp_path, capsys):
    bad = tmp_path / "bad.json5"
    bad.write_text("{ transport: { linkz: {} } }")
    assert main(["run", "--zenoh-config", str(bad), "--duration", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"gazebot: error: --zenoh-config {bad}: not a valid Zenoh configuration")
    assert "\n" not in err and "linkz" in err
    assert main(["router", "--zenoh-config", str(tmp_path / "missing.json5")]) == 2
    assert "no such Zenoh configuration file" in capsys.readouterr().err


def _gazebot(*args: str) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": f"{ROOT}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
           "SDL_VIDEODRIVER": "dummy", "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    return subprocess.Popen([sys.executable, "-m", "gazebot", *args], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@pytest.mark.zenoh
@pytest.mark.slow
def test_simulator_and_engine_over_mutual_tls_and_a_node_without_the_certificate_gets_nothing(
        tmp_path, pki):
    pytest.importorskip("mujoco", reason="needs the [sim] extra (gazebot sim)")
    good, other = pki
    secure = tls_config(tmp_path / "secure.json5", good)
    foreign = tls_config(tmp_path / "foreign.json5", other)  # a certificate of another CA
    port = free_port()
    ns = f"/tls{port}"
    robot = f"tls/localhost:{port}"
    # --no-wait: the robot's tracking is read below before any engine runs.
    sim = _gazebot("sim", "--headless", "--no-wait", "--duration", "120", "--json",
                   "--namespace", ns,
                   "--zenoh-config", str(secure), "--listen", robot)
    sessions = []
    try:
        def session(config: str | None, connect: str):
            s = open_session(BusConfig(listen=(), connect=(connect,), config_file=config))
            sessions.append(s)
            got: list[str] = []
            s.declare_subscriber("**", lambda sample: got.append(str(sample.key_expr)))
            return got

        trusted = session(str(secure), robot)  # the positive control: has the certificate
        plain = session(None, robot)  # TLS without the CA or a client certificate
        intruder = session(str(foreign), robot)  # TLS with another CA's certificate
        tcp = session(None, f"tcp/localhost:{port}")  # not even TLS
        assert wait_until(lambda: len(trusted) > 50, timeout=120), sim.stderr
        engine = _gazebot("run", "--duration", "6", "--json", "--namespace", ns,
                          "--zenoh-config", str(secure), "--connect", robot,
                          "--listen", "tls/localhost:0", "--no-robot-warning", "60")
        out, err = engine.communicate(timeout=180)
        assert engine.returncode == 0, err
        summary = json.loads(out)
        assert summary["robot_seen"] and summary["frames"] > 0 and summary["commands"] > 0
        assert summary["peers"].get("sim") is True
        assert any("/head/command/" in k for k in trusted)  # the engine's commands, over TLS
        assert plain == [] and intruder == [] and tcp == []
    finally:
        for s in sessions:
            s.close()
        sim.send_signal(signal.SIGINT)
        try:
            sim.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            sim.kill()
            sim.communicate()


@pytest.mark.zenoh
def test_user_password_authentication_from_the_config_file_keeps_out_a_node_without_it(
        tmp_path):
    from drivers_fakes import Recorder
    from test_drivers_faults import connected

    from gazebot.core.types import TrackingFrame
    from gazebot.io.drivers.rmw.names import Names
    from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
    from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint
    from gazebot.io.ros2 import convert, topics

    (tmp_path / "users.txt").write_text("robot:robot-secret\nengine:engine-secret\n")

    def auth_file(name: str, user: str | None, password: str | None, dictionary: bool = False):
        usrpwd = {"user": user, "password": password} if user else {}
        if dictionary:
            usrpwd["dictionary_file"] = str(tmp_path / "users.txt")
        path = tmp_path / f"{name}.json5"
        path.write_text(json.dumps({"transport": {"auth": {"usrpwd": usrpwd}}}))
        return str(path)

    names = Names(f"/auth{free_port()}")
    robot_ep = f"tcp/127.0.0.1:{free_port()}"
    sessions = []

    def session(config, listen=(), connect=(robot_ep,)):
        s = open_session(BusConfig(names, listen=listen, connect=connect, config_file=config))
        sessions.append(s)
        return s

    try:
        ep = ZenohRobotEndpoint(session(auth_file("robot", "robot", "robot-secret", True),
                                        listen=(robot_ep,), connect=()), names, "sim")
        drv = ZenohRobotDriver(session(auth_file("engine", "engine", "engine-secret")), names,
                               "engine")
        outsiders = [session(auth_file("wrong", "engine", "guess")), session(None)]
        heard = [Recorder(drv, topics.GIVER_HAND, convert.point_of)]
        for s in outsiders:
            got: list = []
            s.declare_subscriber("**", lambda sample, got=got: got.append(sample))
            heard.append(got)
        assert wait_until(lambda: connected(ep, drv))

        def route_up() -> bool:
            # Seeing each other does not mean the robot's puts reach the engine's subscription
            # yet: a sample, sent until one arrives, does.
            ep.publish_tracking(TrackingFrame.make(-1.0, giver_hand=[1.0, 0.0, 1.0]))
            return bool(heard[0].msgs)

        assert wait_until(route_up, poll=0.05)
        for i in range(5):  # arrive after the route's samples, in order
            ep.publish_tracking(TrackingFrame.make(i / 120, giver_hand=[1.0, 0.0, 1.0]))

        def stamps() -> list[float]:
            return [t for t, _ in heard[0].msgs if t >= 0]

        assert wait_until(lambda: len(stamps()) == 5)
        assert stamps() == pytest.approx([i / 120 for i in range(5)])
        assert heard[1] == [] and heard[2] == []
        for n in (drv, ep):
            n.close()
    finally:
        for s in sessions:
            s.close()
