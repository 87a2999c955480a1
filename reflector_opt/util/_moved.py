"""The earlier public module paths, kept for one release: ``reflector_opt.design._design`` is
now the private ``reflector_opt.design._design``, whose public names the package
(``reflector_opt.design``) gives. Importing an earlier path warns and gives a module with the
private one's names."""

import importlib
import importlib.abc
import importlib.util
import warnings


class MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds ``reflector_opt.….name`` where only ``reflector_opt.…._name`` exists."""

    def find_spec(self, fullname, path, target=None):
        package, _, leaf = fullname.rpartition(".")
        if not package.startswith("reflector_opt") or leaf.startswith("_"):
            return None
        if importlib.util.find_spec(f"{package}._{leaf}") is None:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def exec_module(self, module):
        package, _, leaf = module.__name__.rpartition(".")
        moved = importlib.import_module(f"{package}._{leaf}")
        warnings.warn(
            f"{module.__name__} is deprecated and goes in the next release: import its names "
            f"from {package}",
            DeprecationWarning,
            stacklevel=2,
        )
        module.__dict__.update(
            {name: value for name, value in vars(moved).items() if not name.startswith("__")}
        )
