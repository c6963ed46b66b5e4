"""A directory served over HTTP on 127.0.0.1 with what Neuroglancer needs (docs/cli.md, "Opening
it in Neuroglancer"): CORS, as the viewer runs on another origin, and single byte ranges, as the
multi-resolution format's fragments and shard indices are read by range; Python's http.server
gives neither. The browser test (test_neuroglancer.py) serves its outputs with it, and a user
may serve theirs:

    python3 tests/browser/serve.py DIR [PORT]      (default 9000; Ctrl-C stops it)
"""
import functools
import http.server
import os
import sys
import threading
import time
import urllib.parse


class Handler(http.server.SimpleHTTPRequestHandler):
    """Static files, with CORS (the viewer runs on another origin) and single byte ranges
    (Neuroglancer reads parts of files in the multi-resolution format); records each request's
    time, path and status, a ranged one also under "path#bytes=first-last"."""

    def __init__(self, *args, log, **kwargs):
        self.log = log
        super().__init__(*args, **kwargs)

    def end_headers(self):
        self.send_header("Access-Control-Allow-Origin", "*")
        self.send_header("Access-Control-Expose-Headers", "Content-Range, Content-Length")
        self.send_header("Cache-Control", "no-store")
        super().end_headers()

    def send_head(self):
        self.range_left = None
        spec = self.headers.get("Range")
        if spec is None or not spec.startswith("bytes=") or "," in spec:
            return super().send_head()
        path = self.translate_path(self.path)
        if not os.path.isfile(path):
            return super().send_head()
        size = os.path.getsize(path)
        first, _, last = spec[6:].partition("-")
        if first == "":  # the last N bytes
            first, last = max(0, size - int(last)), size - 1
        else:
            first, last = int(first), min(size - 1, int(last)) if last else size - 1
        if first > last or first >= size:
            self.send_error(416)
            return None
        f = open(path, "rb")
        f.seek(first)
        self.send_response(206)
        self.send_header("Content-Type", self.guess_type(path))
        self.send_header("Content-Range", f"bytes {first}-{last}/{size}")
        self.send_header("Content-Length", str(last - first + 1))
        self.end_headers()
        self.range_left = last - first + 1
        return f

    def copyfile(self, source, outputfile):
        try:
            if self.range_left is None:
                return super().copyfile(source, outputfile)
            outputfile.write(source.read(self.range_left))
        except (BrokenPipeError, ConnectionResetError):
            pass  # a request the viewer cancelled (a level of detail it no longer wants)

    def log_request(self, code="-", size="-"):
        path = urllib.parse.unquote(urllib.parse.urlsplit(self.path).path)
        now = time.time() * 1000
        self.log.append((now, path, int(code)))
        if self.headers.get("Range"):  # also as "path#bytes=first-last", for a Case to expect
            self.log.append((now, f"{path}#{self.headers['Range']}", int(code)))

    def log_message(self, *args):
        pass


class Server:
    """A directory served on 127.0.0.1 (a free port) from a thread, while in a `with`."""

    def __init__(self, directory):
        self.log = []
        handler = functools.partial(Handler, directory=str(directory), log=self.log)
        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}"

    def __enter__(self):
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.httpd.shutdown()
        self.httpd.server_close()
        self.thread.join()


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3) or not os.path.isdir(sys.argv[1]):
        sys.exit("usage: serve.py DIR [PORT]")
    handler = functools.partial(Handler, directory=sys.argv[1], log=[])
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", int(sys.argv[2]) if len(sys.argv) == 3 else 9000), handler)
    print(f"serving {sys.argv[1]} at http://127.0.0.1:{httpd.server_address[1]}/", flush=True)
    try:
        httpd.serve_forever()
    except KeyboardInterrupt:
        pass
