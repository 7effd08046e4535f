"""Physics of the NREL 5 MW turbine on the OC3 Hywind spar (placeholder; filled in as modules land)."""
