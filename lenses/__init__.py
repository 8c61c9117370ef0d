"""Bundled lens prescriptions (TOML), installed as package data."""
