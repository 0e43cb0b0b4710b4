"""The finger in MuJoCo: MJCF export (``export``, ``spec``, ``model``), the quasi-static pull/release run in
MuJoCo (``simulate``), and what MuJoCo's joint friction cannot say about rjcad's friction model (``fit``,
``doc``). Reads manifests and meshes; never imports OpenCASCADE. ``mujoco`` is imported only where a model is run."""
