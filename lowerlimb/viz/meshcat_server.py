"""A meshcat server bound to one address (localhost by default), that dies with its parent.

meshcat's own ``python -m meshcat.servers.zmqserver`` serves the page on every
interface (``0.0.0.0`` and ``[::]``, whatever URL it prints), so anyone on the
network could watch the subject's data; and once started in its own session it
outlives a killed parent, keeping its port. This launcher binds both the web
page and the ZeroMQ socket to ``--host``, and stops when its parent process
goes away.

Run as ``python -m lowerlimb.viz.meshcat_server [--host 127.0.0.1]``; it prints
``zmq_url=…`` and ``web_url=…`` lines, then serves until SIGTERM.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from typing import Any

#: Address the view binds to unless asked otherwise.
DEFAULT_HOST = "127.0.0.1"
#: How often the server checks that its parent is alive, ms.
PARENT_CHECK_MS = 500


def serve_forever(host: str = DEFAULT_HOST) -> None:
    """Start the meshcat bridge on ``host``, print its URLs and serve until SIGTERM/SIGINT or orphaned."""
    import tornado.ioloop
    from meshcat.servers.zmqserver import ZMQWebSocketBridge

    class _Bridge(ZMQWebSocketBridge):  # type: ignore[misc]
        def make_app(self) -> Any:
            app = super().make_app()
            listen = app.listen
            app.listen = lambda port, **kw: listen(port, address=self.host, **kw)
            return app

    bridge = _Bridge(host=host)
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    loop = tornado.ioloop.IOLoop.current()
    parent = os.getppid()

    def stop(*_: object) -> None:
        loop.add_callback_from_signal(loop.stop)

    def check_parent() -> None:
        if os.getppid() != parent:
            loop.stop()

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    tornado.ioloop.PeriodicCallback(check_parent, PARENT_CHECK_MS).start()
    loop.start()


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``python -m lowerlimb.viz.meshcat_server``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default=DEFAULT_HOST, help=f"address to bind (default: {DEFAULT_HOST})")
    serve_forever(parser.parse_args(argv).host)
    return 0


if __name__ == "__main__":
    sys.exit(main())
