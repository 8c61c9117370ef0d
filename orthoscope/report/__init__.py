"""The one place that turns results into text, JSON (:mod:`.jsonout`) and CSV: one module per kind
of result. The science packages never print; the CLI and notebooks use these."""
