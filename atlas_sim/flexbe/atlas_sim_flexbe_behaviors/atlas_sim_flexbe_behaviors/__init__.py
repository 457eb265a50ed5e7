"""FlexBE behaviors for atlas_sim robots (see package.xml)."""
