"""The market on robots: one ROS 2 node per robot trading light contracts, settling on a JSON-RPC chain.

``infomarket ros agent`` is one robot's market agent (its own process, its own key); ``infomarket ros
swarm`` runs the engine as the world in lock step with one agent process per robot and a chain node,
and checks that the chain's ledger equals the engine's (docs/ros.md). Nothing here is imported unless
an ``infomarket ros`` command runs: the ROS 2 wheels are an optional extra (``infomarket[ros]``).
"""
