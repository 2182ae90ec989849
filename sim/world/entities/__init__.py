"""The bodies of the scene, one module per kind: each adds its MJCF, moves, places itself
and tells its truth (base.Entity). The world composes them (sim.world.world)."""
