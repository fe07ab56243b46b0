"""The compiled part of skmotion: the beam Viterbi's inner loops (everything else is in pyproject.toml)."""

from Cython.Build import cythonize
from setuptools import Extension, setup

setup(ext_modules=cythonize([Extension("skmotion.tree._beam", ["skmotion/tree/_beam.pyx"], extra_compile_args=["-O3"])]))
