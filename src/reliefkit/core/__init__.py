"""The small core every technique plugs into: the technique registry and typed options."""
