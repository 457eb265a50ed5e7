"""FlexBE states driving the atlas_sim simulator node (see package.xml)."""
