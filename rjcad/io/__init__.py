"""Files in and out: the one reader of untrusted files (untrusted), TOML configs (config), output sets written
whole or not at all (outputs), the manifest other tools read (manifest), the shipped templates (templates), the
console examples of the pages rjcad generates (console)."""
