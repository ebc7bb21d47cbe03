// Bearer tokens → role, in process (the refusals over gRPC are in daemon_api_test.cc).
#include "daemon/rpc/auth.h"

#include <gtest/gtest.h>

namespace brdf::daemon {
namespace {

const std::vector<TokenConfig> kTokens = {
    {"lab-pc", "operator-secret-0123456789", Role::kOperator},
    {"office", "analyst-secret-0123456789", Role::kAnalyst},
};

TEST(ConstantTimeEqualsTest, ComparesWholeStrings) {
  EXPECT_TRUE(ConstantTimeEquals("abc", "abc"));
  EXPECT_TRUE(ConstantTimeEquals("", ""));
  EXPECT_FALSE(ConstantTimeEquals("abc", "abd"));
  EXPECT_FALSE(ConstantTimeEquals("abc", "ab"));
  EXPECT_FALSE(ConstantTimeEquals("ab", "abc"));
  EXPECT_FALSE(ConstantTimeEquals(std::string("ab\0", 3), "ab"));
}

TEST(AuthenticatorTest, MapsEachTokenToItsRoleAndName) {
  const Authenticator auth(kTokens);
  Caller caller;
  AuthFailure failure = AuthFailure::kNone;
  ASSERT_TRUE(auth.Identify("Bearer operator-secret-0123456789", &caller, &failure));
  EXPECT_EQ(caller.role, Role::kOperator);
  EXPECT_EQ(caller.name, "lab-pc");
  EXPECT_EQ(caller.ToActor().role, "operator");
  ASSERT_TRUE(auth.Identify("bearer analyst-secret-0123456789", &caller, &failure));
  EXPECT_EQ(caller.role, Role::kAnalyst);
  EXPECT_EQ(caller.name, "office");
}

TEST(AuthenticatorTest, RefusesMissingMalformedAndUnknownTokens) {
  const Authenticator auth(kTokens);
  Caller caller;
  AuthFailure failure = AuthFailure::kNone;
  EXPECT_FALSE(auth.Identify("", &caller, &failure));
  EXPECT_EQ(failure, AuthFailure::kMissing);
  EXPECT_FALSE(auth.Identify("Basic operator-secret-0123456789", &caller, &failure));
  EXPECT_EQ(failure, AuthFailure::kMalformed);
  EXPECT_FALSE(auth.Identify("Bearer ", &caller, &failure));
  EXPECT_EQ(failure, AuthFailure::kMalformed);
  for (const char* wrong :
       {"Bearer operator-secret-012345678", "Bearer operator-secret-01234567890",
        "Bearer Operator-secret-0123456789", "Bearer x"}) {
    EXPECT_FALSE(auth.Identify(wrong, &caller, &failure)) << wrong;
    EXPECT_EQ(failure, AuthFailure::kUnknown) << wrong;
  }
  EXPECT_FALSE(auth.Identify("Bearer " + std::string(5000, 'a'), &caller, &failure));
  EXPECT_EQ(failure, AuthFailure::kMalformed);
}

TEST(AuthenticatorTest, WithoutTokensEveryCallerIsAnAnonymousOperator) {
  const Authenticator auth({});
  EXPECT_FALSE(auth.enabled());
  Caller caller;
  AuthFailure failure = AuthFailure::kNone;
  ASSERT_TRUE(auth.Identify("", &caller, &failure));
  EXPECT_EQ(caller.role, Role::kOperator);
  EXPECT_EQ(caller.name, "anonymous");
}

}  // namespace
}  // namespace brdf::daemon
