"""The settings of an in-process suite under test (what `serve`'s command line would give)."""

from argparse import Namespace


def suite_args(byproducts_dir, **overrides) -> Namespace:
    """Suite arguments with byproducts in ``byproducts_dir``, the builtin synthesizer and short
    service timeouts; ``overrides`` replace any of them."""
    values = dict(config_dir='', byproducts_dir=str(byproducts_dir), backend='builtin',
                  slugs_executable='slugs', synthesis_timeout=60.0, service_timeout=2.0)
    values.update(overrides)
    return Namespace(**values)
