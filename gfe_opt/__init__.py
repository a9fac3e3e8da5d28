"""gfe-opt: finite-element model updating with generic elements and physical realisation."""
