"""A static file server on 127.0.0.1 for the browser test: serves DIR on a free port, prints the
port on stdout (one line) and serves until killed. A POST to /shot/NAME.png stores its body as
DIR/shot/NAME.png: the page sends its canvas there (headless Chromium's own --screenshot does not wait
for the page's asynchronous loading). Python's standard library only."""
import functools
import http.server
import os
import re
import sys


class Quiet(http.server.SimpleHTTPRequestHandler):
    extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, ".js": "text/javascript", ".mjs": "text/javascript", ".glb": "model/gltf-binary"}

    def log_message(self, *args):
        pass

    def do_POST(self):
        name = re.fullmatch(r"/shot/([A-Za-z0-9_-]+\.png)", self.path)
        if not name:
            self.send_error(404)
            return
        body = self.rfile.read(int(self.headers.get("Content-Length", 0)))
        folder = os.path.join(self.directory, "shot")
        os.makedirs(folder, exist_ok=True)
        partial = os.path.join(folder, name.group(1) + ".part")
        with open(partial, "wb") as f:
            f.write(body)
        os.replace(partial, os.path.join(folder, name.group(1)))
        self.send_response(204)
        self.end_headers()


handler = functools.partial(Quiet, directory=sys.argv[1])
server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
print(server.server_address[1], flush=True)
server.serve_forever()
