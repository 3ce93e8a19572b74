# HAProxy from Debian's package, for deploy/compose.yaml.
FROM debian:12-slim
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends haproxy \
 && rm -rf /var/lib/apt/lists/*
COPY haproxy.cfg /etc/haproxy/haproxy.cfg
COPY errors/*.http /etc/haproxy/errors/
EXPOSE 8080
# -W (master-worker): the master handles SIGTERM. As PID 1, a plain `haproxy -db` ignores it
# (the kernel does not apply a default action to PID 1), so `docker stop` waited 10 s and
# killed it (137); with -W it exits in 0.2 s.
CMD ["haproxy", "-W", "-db", "-f", "/etc/haproxy/haproxy.cfg"]
