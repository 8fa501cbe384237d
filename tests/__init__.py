"""artic's tests: a package, so that they share helpers as modules (tests.helpers)."""
