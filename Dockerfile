# grip service image: built on Debian 12 with the project's own setup script, run as a
# non-root user with the job database on a volume.
#   docker build -t grip .
#   docker run -d -p 8080:8080 -v grip-data:/var/lib/grip --name grip grip
#   docker stop grip     # SIGTERM: running jobs get GRIP_GRACE seconds (5 here) to finish
# Grace and stop timeout fit together: `docker stop` waits 10 s by default before SIGKILL; the
# service takes GRIP_GRACE (5 s) for running jobs, then requeues what is left and exits, well
# inside those 10 s. A longer GRIP_GRACE needs `docker stop -t` / `--stop-timeout` (compose:
# stop_grace_period) at least GRIP_GRACE + 5 s.
# A bind-mounted data folder (-v /srv/grip:/var/lib/grip) must be writable by user 10001, group
# 10001 (chown 10001:10001 /srv/grip).
# Several replicas on one PostgreSQL: GRIP_DB=postgresql://... (deploy/compose.yaml).
FROM debian:12-slim AS build
WORKDIR /src
COPY scripts/setup.sh scripts/setup.sh
RUN bash scripts/setup.sh --service && rm -rf /var/lib/apt/lists/*
COPY . .
RUN cmake -S . -B /build -G Ninja -DCMAKE_BUILD_TYPE=Release \
 && cmake --build /build --target grip \
 && strip /build/apps/grip /build/apps/grip-server

# SuiteSparse is linked from its static archives (solver/CMakeLists.txt); its METIS, LAPACK
# and OpenMP stay shared.
FROM debian:12-slim
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      libcpp-httplib0.11 libspdlog1.10 libfmt9 libsqlite3-0 libpq5 libmetis5 liblapack3 libgomp1 libzstd1 libssl3 \
 && rm -rf /var/lib/apt/lists/* \
 && groupadd --system --gid 10001 grip \
 && useradd --system --uid 10001 --gid 10001 --home-dir /var/lib/grip --create-home grip
# grip serve and grip healthcheck run grip-server from grip's directory (apps/CMakeLists.txt).
COPY --from=build /build/apps/grip /build/apps/grip-server /usr/local/bin/
COPY --from=build /src/schemas /usr/local/share/grip/schemas
ENV GRIP_HOST=0.0.0.0 \
    GRIP_PORT=8080 \
    GRIP_DB=/var/lib/grip/grip.sqlite \
    GRIP_GRACE=5 \
    GRIP_SCHEMAS=/usr/local/share/grip/schemas
USER grip
WORKDIR /var/lib/grip
VOLUME /var/lib/grip
EXPOSE 8080
STOPSIGNAL SIGTERM
HEALTHCHECK --interval=15s --timeout=5s --start-period=10s --retries=3 CMD ["grip", "healthcheck"]
ENTRYPOINT ["grip"]
CMD ["serve"]
