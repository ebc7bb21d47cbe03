"""The client's version and the API it speaks (read by pyproject.toml without importing)."""

__version__ = "0.2.0"
# The protobuf package of brdfd's API these stubs and calls are for (proto/brdf/v1/*.proto).
PROTO_PACKAGE = "brdf.v1"
