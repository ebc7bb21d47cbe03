"""`python3 -m brdf_client [--version]`: which client this is and which API it speaks."""

import sys

from . import about


def main() -> int:
    """Prints the version, the API's protobuf package and digest, and where the stubs are."""
    info = about()
    print(f"brdf_client {info['version']}: API {info['proto_package']} "
          f"(.proto sha256 {info['proto_digest'] or 'unknown'}), stubs in {info['stubs']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
