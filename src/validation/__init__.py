"""Validation: logs, the closed-loop harness, error criteria, the campaign and the CLI."""
