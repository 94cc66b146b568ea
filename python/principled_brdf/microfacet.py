"""Microfacet toolkit (SPEC §4)."""
