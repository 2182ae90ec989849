"""The shipped BlazePose ONNX files and the int8 candidates, made in .venv-models (`make
models`, `make models-int8`): `python -m tools.models.convert` from the checkout's top folder,
so the models venv imports these modules without installing the project."""
