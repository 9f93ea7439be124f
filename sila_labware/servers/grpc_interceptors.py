"""Put gRPC server interceptors in front of a SiLA server: the lock guard, the initiation checks.

Why: some answers must come before sila2 handles a call (a wrong lock token, a bad parameter of an
observable command: sila2 would otherwise accept the call and fail its execution later), and gRPC
takes interceptors only when its server is built. sila2 builds its gRPC server in
`SilaServer.__init__` without a way to pass any, so `serve_with_interceptors` builds a new one with
them and registers on it everything the old one served. Call it once, after every feature was
added and before the server starts.

Threads: the caller's, once, at start-up.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import grpc
from sila2.framework.abc.binary_transfer_handler import grpc_module as binary_transfer_grpc_module
from sila2.server import SilaServer

GRPC_WORKERS = 100
"""Handler threads of the rebuilt gRPC server: sila2's default (`SilaServer(max_grpc_workers=100)`)."""


def serve_with_interceptors(server: SilaServer, interceptors: list[grpc.ServerInterceptor]) -> None:
    """Give `server` a new (not yet started) gRPC server with `interceptors`, serving what the old
    one did. Features added later would register on the new one (`set_feature_implementation` reads
    `server.grpc_server`), but interceptors added by a second call would replace these."""
    if server.running:
        raise RuntimeError("interceptors must be put in place before the server starts")
    grpc_server = grpc.server(
        ThreadPoolExecutor(
            max_workers=GRPC_WORKERS, thread_name_prefix=f"grpc-executor-{server.server_uuid}"
        ),
        interceptors=interceptors,
    )
    for servicer in server.feature_servicers.values():
        feature = servicer.feature
        getattr(feature._grpc_module, f"add_{feature._identifier}Servicer_to_server")(servicer, grpc_server)
    binary_transfer = server.binary_transfer_handler
    binary_transfer_grpc_module.add_BinaryUploadServicer_to_server(
        binary_transfer.upload_servicer, grpc_server
    )
    binary_transfer_grpc_module.add_BinaryDownloadServicer_to_server(
        binary_transfer.download_servicer, grpc_server
    )
    server.grpc_server = grpc_server
