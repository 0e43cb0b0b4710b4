"""CadQuery builders: spiral springs, the joint module, the finger, and exports."""
