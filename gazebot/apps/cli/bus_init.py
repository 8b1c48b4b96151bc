"""``gazebot bus init DIR``: what a lab needs for an authenticated bus (issue 30): a certificate
authority, a certificate and key per node role and a Zenoh configuration per role (JSON5) with
mutual TLS and access control by certificate common name, so that only the engine's identity may
publish head commands, eyes and arm goals and claim the robot, only trackers tracking, and only
the robot its joint states, robot events and its own liveliness. Every gazebot node takes the
role's file with ``--zenoh-config DIR/ROLE.json5``; docs/bus.md says how.

Certificates are made with the ``openssl`` command line. The CA's key (``DIR/ca/ca.key``) signs
new certificates only: keep it off the robots' machines.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

from gazebot.apps.cli.errors import UsageError
from gazebot.io.drivers.rmw.graph import ADMIN_SPACE
from gazebot.io.drivers.rmw.names import Names, mangle
from gazebot.io.ros2 import topics

#: Zenoh's ACL message kinds a node only reads or asks with (every role may).
READ_MESSAGES = ("declare_subscriber", "query", "declare_queryable", "reply",
                 "declare_liveliness_subscriber", "liveliness_query")
ALL_MESSAGES = (*READ_MESSAGES, "put", "delete", "liveliness_token")


@dataclass(frozen=True)
class Role:
    """A node role: its certificate's common name (``name``), the node names its liveliness
    tokens may carry (Zenoh key-expression chunks: ``engine$*`` is every name starting with
    ``engine``), the topics it may publish and whether it may claim the robot."""

    name: str
    nodes: tuple[str, ...]
    publishes: tuple[str, ...] = ()
    claims: bool = False
    routes: bool = False  # a router forwards every role's traffic: its nodes trust it
    summary: str = ""


_EVERYONE = (topics.EVENTS.name, topics.DIAGNOSTICS.name)
_TRACKING = (*(t.name for t in topics.TRACKING.values()), topics.TF.name)
_ROBOT = (topics.JOINT_STATES.name, topics.ROBOT_EVENTS.name, topics.GRIPPER.name,
          topics.LOAD_SHARE.name)
_ENGINE = (topics.HEAD_COMMAND.name, topics.GAZE_TARGET.name, topics.EYES.name,
           topics.EYE_IMAGE.name, topics.PHASE.name, topics.ARM_COMMAND.name,
           topics.ARM_MODE.name, topics.TF.name)

ROLES: dict[str, Role] = {r.name: r for r in (
    Role("engine", ("engine$*",), _ENGINE, claims=True,
         summary="gazebot run: head commands, eyes, gaze target, phase, arm goals"),
    Role("robot", ("sim", "robot$*"), _ROBOT,
         summary="a robot bridge: joint states, robot events, gripper, load share"),
    Role("tracker", ("tracker$*", "mocap$*", "face_tracker$*"), _TRACKING,
         summary="motion capture: the tracking topics and /tf"),
    Role("sim", ("sim",), (*_ROBOT, *_TRACKING),
         summary="gazebot sim: the robot and its own tracking"),
    Role("display", ("display$*",), summary="gazebot display: reads only"),
    Role("recorder", ("recorder$*", "tool$*", "gazebot$*"),
         summary="recorders and tools: read only"),
    Role("router", ("router$*",), routes=True,
         summary="gazebot router / zenohd: forwards the others' traffic, enforces the rules"),
)}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bus", help="set up an authenticated bus (certificates, Zenoh configs)",
                       description=__doc__.split("\n\n")[0])
    bus_sub = p.add_subparsers(dest="bus_command", metavar="ACTION")
    bus_sub.required = True
    init = bus_sub.add_parser(
        "init", help="write a CA, a certificate per role and a Zenoh config per role",
        description="Write DIR/ca/, DIR/<role>/{cert,key}.pem and DIR/<role>.json5 for the "
        f"roles {', '.join(ROLES)}: mutual TLS and access control by certificate name.")
    init.add_argument("dir", metavar="DIR", help="folder to write (created; must be empty)")
    init.add_argument("--host", action="append", default=[], metavar="NAME",
                      help="a host name or IP address the nodes listen on, repeatable "
                      "(certificates name it; default: localhost and 127.0.0.1)")
    init.add_argument("--namespace", default="/gazebot", metavar="NS",
                      help="ROS namespace of the robot's topics (default /gazebot)")
    init.add_argument("--domain-id", type=int, default=0, metavar="N",
                      help="ROS domain id (default 0)")
    init.add_argument("--days", type=int, default=365, help="certificate validity (days)")
    init.set_defaults(func=handle)


def handle(args: argparse.Namespace) -> int:
    try:
        names = Names(args.namespace, domain_id=args.domain_id)
    except ValueError as exc:
        raise UsageError(f"--namespace/--domain-id: {exc}") from None
    if not 1 <= args.days <= 36500:
        raise UsageError(f"--days: expected 1..36500, got {args.days}")
    written = init_bus(Path(args.dir), names, tuple(args.host) or ("localhost", "127.0.0.1"),
                       args.days)
    for role, path in written.items():
        print(f"{role:9s} --zenoh-config {path}    ({ROLES[role].summary})")
    return 0


# -- certificates ----------------------------------------------------------------------------


def _openssl(*args: str, cwd: Path) -> None:
    try:
        subprocess.run(["openssl", *args], cwd=cwd, check=True, capture_output=True, text=True)
    except subprocess.CalledProcessError as exc:
        raise UsageError(f"openssl {args[0]} failed: {exc.stderr.strip()[:300]}") from None


def _make_ca(folder: Path, days: int) -> None:
    folder.mkdir(parents=True)
    _openssl("req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes",
             "-keyout", "ca.key", "-out", "ca.pem", "-days", str(days),
             "-subj", "/CN=gazebot bus CA", cwd=folder)
    (folder / "ca.key").chmod(0o600)


def _make_cert(folder: Path, ca: Path, cn: str, hosts: tuple[str, ...], days: int) -> None:
    """A key and a certificate for ``cn`` signed by the CA in ``ca``, for both ends of a TLS
    link (server and client use), valid for ``hosts``."""
    folder.mkdir(parents=True)
    _openssl("req", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes",
             "-keyout", "key.pem", "-out", "node.csr", "-subj", f"/CN={cn}", cwd=folder)
    sans = ",".join(f"IP:{h}" if _is_ip(h) else f"DNS:{h}" for h in hosts)
    (folder / "ext.cnf").write_text(
        f"subjectAltName={sans}\nbasicConstraints=CA:FALSE\n"
        "keyUsage=digitalSignature\nextendedKeyUsage=serverAuth,clientAuth\n")
    _openssl("x509", "-req", "-in", "node.csr", "-CA", str(ca / "ca.pem"), "-CAkey",
             str(ca / "ca.key"), "-CAcreateserial", "-out", "cert.pem", "-days", str(days),
             "-extfile", "ext.cnf", cwd=folder)
    (folder / "key.pem").chmod(0o600)
    for tmp in ("node.csr", "ext.cnf"):
        (folder / tmp).unlink()


def _is_ip(host: str) -> bool:
    import ipaddress

    try:
        ipaddress.ip_address(host)
    except ValueError:
        return False
    return True


# -- access control --------------------------------------------------------------------------


def _data_keys(names: Names, topic_names: tuple[str, ...]) -> list[str]:
    return [f"{names.domain_id}/{names.resolve(t).lstrip('/')}/**" for t in topic_names]


def _token_keys(names: Names, role: Role) -> list[str]:
    """The liveliness tokens a role may declare: its nodes, their subscriptions, and publishers
    of the topics it may publish (``@ros2_lv/<domain>/<zid>/<node id>/<id>/<kind>/<enclave>/
    <namespace>/<node>/...``)."""
    base = f"{ADMIN_SPACE}/{names.domain_id}/*/*/*"
    keys = []
    for node in role.nodes:
        keys.append(f"{base}/NN/*/*/{node}")
        keys.append(f"{base}/MS/*/*/{node}/**")
        for t in (*_EVERYONE, *role.publishes):
            keys.append(f"{base}/MP/*/*/{node}/{mangle(names.resolve(t))}/**")
    if role.claims:
        from gazebot.io.drivers.ownership import OWNER_SPACE

        keys.append(f"{OWNER_SPACE}/{names.domain_id}/**")
    return keys


def access_control(names: Names) -> dict[str, object]:
    """Zenoh's ``access_control`` section for every role (the same in each node's config:
    each node checks what arrives from its links; a router checks what it forwards)."""
    from gazebot.io.drivers.ownership import OWNER_SPACE
    from gazebot.io.drivers.zenoh_node import HISTORY_SPACE

    # ``**`` does not match a chunk starting with ``@``: the admin spaces are named.
    anything = ["**", f"{ADMIN_SPACE}/**", f"{OWNER_SPACE}/**", f"{HISTORY_SPACE}/**"]
    rules: list[dict[str, object]] = [
        {"id": "send_anything", "permission": "allow", "flows": ["egress"],
         "messages": list(ALL_MESSAGES), "key_exprs": anything},
        {"id": "read_and_ask", "permission": "allow", "flows": ["ingress"],
         "messages": list(READ_MESSAGES), "key_exprs": anything},
        {"id": "routed", "permission": "allow", "flows": ["ingress"],
         "messages": list(ALL_MESSAGES), "key_exprs": anything},
    ]
    policies = []
    for role in ROLES.values():
        rule_ids = ["send_anything", "read_and_ask"]
        if role.routes:
            rule_ids.append("routed")
        else:
            rules.append({"id": f"{role.name}_publishes", "permission": "allow",
                          "flows": ["ingress"], "messages": ["put", "delete"],
                          "key_exprs": _data_keys(names, (*_EVERYONE, *role.publishes))})
            rules.append({"id": f"{role.name}_tokens", "permission": "allow",
                          "flows": ["ingress"], "messages": ["liveliness_token"],
                          "key_exprs": _token_keys(names, role)})
            rule_ids += [f"{role.name}_publishes", f"{role.name}_tokens"]
        policies.append({"id": role.name, "rules": rule_ids, "subjects": [role.name]})
    subjects = [{"id": r.name, "cert_common_names": [r.name]} for r in ROLES.values()]
    return {"enabled": True, "default_permission": "deny", "rules": rules,
            "subjects": subjects, "policies": policies}


def zenoh_config(folder: Path, role: str, acl: dict[str, object]) -> dict[str, object]:
    """One role's Zenoh configuration: mutual TLS with the role's certificate, the bus's
    access control."""
    tls = {"root_ca_certificate": str(folder / "ca" / "ca.pem"),
           "listen_certificate": str(folder / role / "cert.pem"),
           "listen_private_key": str(folder / role / "key.pem"),
           "connect_certificate": str(folder / role / "cert.pem"),
           "connect_private_key": str(folder / role / "key.pem"),
           "enable_mtls": True}
    return {"transport": {"link": {"tls": tls}}, "access_control": acl}


def init_bus(folder: Path, names: Names, hosts: tuple[str, ...], days: int = 365,
             ) -> dict[str, Path]:
    """Write the CA, each role's certificate and key and each role's Zenoh configuration under
    ``folder``; returns role -> configuration file.

    Raises:
        UsageError: ``folder`` is not empty, or ``openssl`` is missing or fails.
    """
    if shutil.which("openssl") is None:
        raise UsageError("the openssl command is needed to make the certificates")
    if folder.exists() and any(folder.iterdir()):
        raise UsageError(f"{folder}: not empty (bus init writes a new CA; use another folder)")
    folder = folder.resolve()
    folder.mkdir(parents=True, exist_ok=True)
    _make_ca(folder / "ca", days)
    acl = access_control(names)
    written = {}
    for role in ROLES:
        _make_cert(folder / role, folder / "ca", role, hosts, days)
        path = folder / f"{role}.json5"
        path.write_text(f"// gazebot bus init: the {role} role "
                        f"({ROLES[role].summary}); namespace {names.namespace}, "
                        f"domain {names.domain_id}\n" + json.dumps(zenoh_config(folder, role,
                                                                              acl), indent=2))
        written[role] = path
    return written


