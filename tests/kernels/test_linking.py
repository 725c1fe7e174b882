"""kernels/_linking.py: a cached kernel loaded with its bitcode unparsed, parsed when needed (issue 36)."""

import os
import subprocess
import sys

LOADED = """
import numba
from emaphm.kernels import _linking
from emaphm.kernels.sensors import quantise
value = quantise(0.123456, 0.01, 1.0)
library = quantise.overloads[quantise.signatures[0]].library
engine = library._codegen._engine
print(value, type(library).__name__, hasattr(library, _linking.BITCODE))
if sys.argv[1] == "link":  # a new function that calls the loaded one links its module in
    @numba.njit
    def twice(x):
        return 2.0 * quantise(x, 0.01, 1.0)
    print(twice(0.123456) == 2.0 * value, hasattr(library, _linking.BITCODE))
else:  # a name the bitcode defines, asked of the engine
    name = quantise.overloads[quantise.signatures[0]].fndesc.llvm_func_name
    print(engine.is_symbol_defined(name), hasattr(library, _linking.BITCODE))
"""


def run(how: str, cache: str) -> list[str]:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    code = "import sys\n" + LOADED
    out = subprocess.run(
        [sys.executable, "-c", code, how], capture_output=True, text=True, env=env, check=True
    )
    return out.stdout.split()


def test_a_cached_kernel_loads_lazily_and_is_parsed_when_linked_or_looked_up(tmp_path):
    first = run("link", str(tmp_path))  # compiled here and cached: numba's own library
    assert first[1] == "JITCodeLibrary" and first[2] == "False", first
    linked = run("link", str(tmp_path))  # loaded from the cache: the bitcode pending, then linked
    assert linked[0] == first[0]
    assert linked[1:] == ["LazyJITCodeLibrary", "True", "True", "False"], linked
    looked_up = run("lookup", str(tmp_path))
    assert looked_up[1:] == ["LazyJITCodeLibrary", "True", "True", "False"], looked_up
