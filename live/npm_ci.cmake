# `npm ci` of the gale live page's dependencies (web/package-lock.json: three.js) into WEB,
# run by the build (cmake -DNPM=... -DWEB=... -P npm_ci.cmake). Offline with no npm cache it
# warns instead of failing the build: the server then answers the page's three.js requests
# with a 404 naming this step, the browser test skips, and the next build tries again.
execute_process(COMMAND ${NPM} ci --prefix ${WEB} --no-audit --no-fund --prefer-offline --loglevel=error
                RESULT_VARIABLE rc)
if(rc EQUAL 0)
    file(TOUCH ${WEB}/node_modules/.gale-stamp)
else()
    message(WARNING "npm ci failed (offline?): the gale live page has no three.js until it succeeds")
endif()
