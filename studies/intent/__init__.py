"""Can the intent stage earn its place? The analyses behind docs/intent/verdict.md."""
