"""Constitutive laws in the lamina frame."""
