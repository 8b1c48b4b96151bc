"""The rmw_zenoh wire: ROS 2 messages on Zenoh exactly as ``rmw_zenoh_cpp`` puts them there.

One concept per module:

* :mod:`.names`: ROS names (namespace, ``--remap FROM:=TO``), key mangling, DDS type names.
* :mod:`.qos`: the QoS profile and its encoding in liveliness tokens.
* :mod:`.attachment`: the attachment of every sample (sequence number, source timestamp, GID).
* :mod:`.graph`: liveliness tokens of nodes, publishers and subscriptions under ``@ros2_lv``
  and the graph they describe.
* :mod:`.node`: a ROS 2 node on a Zenoh session: publishers, subscriptions, graph.

Message types, CDR and RIHS01 type hashes are :mod:`gazebot.io.ros2`'s (rosbags).

Key expressions (rmw_zenoh ``docs/design.md``):

* data: ``<domain_id>/<topic without leading slash>/<DDS type name>/<RIHS01 hash>``
* node token: ``@ros2_lv/<domain_id>/<zid>/<node id>/<node id>/NN/<enclave>/<namespace>/<name>``
* endpoint token: ``@ros2_lv/<domain_id>/<zid>/<node id>/<entity id>/MP|MS/<enclave>/<namespace>/
  <node>/<topic>/<DDS type name>/<hash>/<qos>`` (``/`` in names mangled to ``%``).
"""
