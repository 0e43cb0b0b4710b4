"""Physics: pure functions over numbers (no CAD imports)."""
