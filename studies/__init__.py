"""Studies: questions about the pipeline and the test bed, each answered once in docs/.

Not part of the product: monopic and sim import nothing from here (a lint-imports contract
in pyproject.toml), so a study can read anything the product computes without the product
carrying it. Each sub-package is one study, its README the question, the command and where
the answer is written; run them from the checkout's top folder as modules
(`.venv/bin/python -m studies.intent.crossfit ...`). studies/README.md lists them.
"""
